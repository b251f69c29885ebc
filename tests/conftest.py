"""Shared test fixtures: the reference data beside the project (../shared), skipped where absent."""

from __future__ import annotations

import os

# One BLAS/OpenMP thread per process: the dense solves of the tests are small, and threaded BLAS on a
# shared 2-core machine made them up to 100x slower. Set before numpy is imported by any test module.
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

from pathlib import Path  # noqa: E402

import pytest  # noqa: E402

SHARED = Path(__file__).resolve().parents[1].parent / "shared"


@pytest.fixture(scope="session")
def shared_dir() -> Path:
    """../shared (paper and validation data); tests that need it skip with a reason where it is absent."""
    if not (SHARED / "validation-data").is_dir():
        pytest.skip(f"reference data not found at {SHARED}/validation-data (a user's clone has no "
                    "../shared; see README)")
    return SHARED
