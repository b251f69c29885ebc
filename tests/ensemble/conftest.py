"""Shared pieces of the ensemble tests: a radial fracture scene at the fast preset (a fraction of a second per
member) and a writer of sweep files beside it."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

BASE = """
[run]
end_time = "60 s"
physics = ["fracture"]
preset = "fast"

[rock]
youngs_modulus = "40 GPa"
poisson_ratio = 0.15
toughness = "1 MPa*m**0.5"
leakoff_coefficient = "2e-7 m/s**0.5"
min_stress = "60 MPa"

[[rock.layers]]
top = "0 m"
bottom = "990 m"
min_stress = "62 MPa"

[fluid]
viscosity = "0.08 Pa*s"

[injection]
depth = "1000 m"
schedule = [{ until = "60 s", rate = "0.053 m**3/s" }]

[mesh]
cell_size = "2.0 m"

[output]
every = "60 s"
"""


@pytest.fixture(scope="session")
def base_text() -> str:
    """The base scene's TOML text."""
    return BASE


@pytest.fixture(scope="session")
def scheduler():
    """The address of a local cluster made as ``hfgpu sweep`` makes its own (2 workers), shared by the tests
    that do not test the cluster itself (each cluster start costs seconds)."""
    from hfgpu.ensemble.execute import _client

    client, cluster = _client(2, None)
    yield cluster.scheduler_address
    client.close()
    cluster.close()


@pytest.fixture(autouse=True)
def _one_thread(monkeypatch):
    """Single-threaded BLAS in this process too (the machine's cores are shared)."""
    monkeypatch.setenv("OMP_NUM_THREADS", "1")


@pytest.fixture
def write_sweep(tmp_path):
    """write_sweep(body, base=BASE) -> path of a sweep file whose ``scene = "base.toml"`` is written beside it."""

    def write(body: str, base: str = BASE, name: str = "sweep.toml") -> Path:
        (tmp_path / "base.toml").write_text(base, encoding="utf-8")
        path = tmp_path / name
        path.write_text('scene = "base.toml"\n' + textwrap.dedent(body), encoding="utf-8")
        return path

    return write
