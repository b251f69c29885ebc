"""Shared test fixtures: the reference data beside the project (../shared), skipped where absent."""

from __future__ import annotations

from pathlib import Path

import pytest

SHARED = Path(__file__).resolve().parents[1].parent / "shared"


@pytest.fixture(scope="session")
def shared_dir() -> Path:
    """../shared (paper and validation data); tests that need it skip with a reason where it is absent."""
    if not (SHARED / "validation-data").is_dir():
        pytest.skip(f"reference data not found at {SHARED}/validation-data (a user's clone has no "
                    "../shared; see README)")
    return SHARED
