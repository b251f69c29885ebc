"""What a simulator hands to its output sink: snapshots and balance records (plain data, SI units).

Simulators call, on any object with these methods (the HDF5 writer, a Rerun recorder, a test list):

    sink.fracture_snapshot(FractureSnapshot)   # every [output] every, and at the end
    sink.fracture_balance(BalanceRecord)        # every accepted time step
    sink.proppant_snapshot(ProppantSnapshot)    # every [output] every, and at the end
    sink.proppant_balance(SolidBalanceRecord)   # every fluid step

Grid arrays are (nz, nx), row 0 at the shallowest depth z0, column 0 at x0 (centres of cell [0, 0]);
depth z is positive downward.
"""

from __future__ import annotations

import math

from dataclasses import dataclass, field, fields

import numpy as np


@dataclass(frozen=True)
class GridFrame:
    """Placement of a uniform grid: cell sizes and the centre of cell [0, 0] [m]."""

    dx: float
    dz: float
    x0: float
    z0: float

    def centres(self, nz: int, nx: int) -> tuple[np.ndarray, np.ndarray]:
        """(x, z) cell-centre coordinates, each 1-D."""
        return self.x0 + self.dx * np.arange(nx), self.z0 + self.dz * np.arange(nz)

    @classmethod
    def of(cls, values) -> "GridFrame":
        """The frame stored as a mapping with the keys dx, dz, x0, z0 (an HDF5 group's attributes, a checkpoint's
        group)."""
        return cls(**{f.name: float(values[f.name]) for f in fields(cls)})


@dataclass(frozen=True)
class FractureSnapshot:
    """The fracture at one time.

    width [m] is 0 outside the fracture; pressure [Pa] is the fluid pressure (0 outside);
    leakoff_rate [m/s] is the leak-off volume rate per unit fracture area over the last step (Carter,
    both faces); opening_time [s] is the time each cell opened (NaN outside).
    """

    time: float
    frame: GridFrame
    width: np.ndarray
    pressure: np.ndarray
    leakoff_rate: np.ndarray
    opening_time: np.ndarray
    extras: dict[str, np.ndarray] = field(default_factory=dict)

    def __repr__(self) -> str:
        return (f"FractureSnapshot(time={self.time:.6g} s, {self.frame}, "
                f"{_shapes({name: getattr(self, name) for name in _FRACTURE_ARRAYS} | self.extras)})")


@dataclass(frozen=True)
class BalanceRecord:
    """One accepted fracture step: the fluid volume balance [m^3], injected = stored + leaked (to the tolerance
    of the solver), and the pressure history a treatment is read by: the fluid pressure in the injection cell
    [Pa], the net pressure there (that pressure minus the minimum stress at the injection depth) [Pa], the
    fluid efficiency stored / injected, the footprint's area [m^2], length and height [m] (geometry.py), the
    width of the injection cell [m]. The history fields are NaN where a record does not carry them (a results
    file written before they existed)."""

    time: float
    injected: float
    stored: float
    leaked: float
    injection_pressure: float = math.nan
    net_pressure: float = math.nan
    efficiency: float = math.nan
    area: float = math.nan
    length: float = math.nan
    height: float = math.nan
    inlet_width: float = math.nan


@dataclass(frozen=True)
class StageRecord:
    """One accepted step of a stage of several clusters (hfgpu.fracture.stage): the wellbore pressure p_w [Pa]
    (NaN while the pumps are stopped), each cluster's rate q_i [m^3/s] over the step and its own balance
    record (its inlet pressure, net pressure, volumes and footprint)."""

    time: float
    wellbore_pressure: float
    rates: np.ndarray
    clusters: tuple[BalanceRecord, ...]


@dataclass(frozen=True)
class StageSnapshot:
    """One cluster's fracture snapshot in a stage of several clusters: ``cluster`` its index in the order of
    ``[completion] positions``."""

    cluster: int
    snapshot: FractureSnapshot


@dataclass(frozen=True)
class ProppantSnapshot:
    """Parcels and grid fields of the MP-PIC model at one time.

    parcels: 1-D arrays x, z [m], u, v [m/s], radius [m], density [kg/m^3], particles (per parcel),
    state (0 suspended, 1 bridged/stopped), class_id (index into the scene's proppant classes).
    grid: (nz, nx) volume_fraction, pressure [Pa], width [m]; fluid_u (nz, nx+1) on x-faces and
    fluid_v (nz+1, nx) on z-faces [m/s].
    """

    time: float
    frame: GridFrame
    parcels: dict[str, np.ndarray]
    grid: dict[str, np.ndarray]

    def __repr__(self) -> str:
        return (f"ProppantSnapshot(time={self.time:.6g} s, {self.frame}, parcels: {_shapes(self.parcels)}, "
                f"grid: {_shapes(self.grid)})")


@dataclass(frozen=True)
class SolidBalanceRecord:
    """Proppant solid volume [m^3]: injected = in_domain + outflow + screened_out (to round-off).

    screened_out: solid volume scheduled at the inlets but held back because their cells were packed
    (screen-out, :mod:`hfgpu.proppant.injection`)."""

    time: float
    injected: float
    in_domain: float
    outflow: float
    screened_out: float = 0.0


_FRACTURE_ARRAYS = ("width", "pressure", "leakoff_rate", "opening_time")


def _shapes(arrays: dict[str, np.ndarray]) -> str:
    """``name(shape)`` of each array (``name=value`` of a scalar), comma separated: a snapshot's repr without its
    arrays' values."""
    return ", ".join(f"{name}={float(array):.6g}" if np.ndim(array) == 0 else f"{name}{tuple(np.shape(array))}"
                     for name, array in arrays.items())


class MemorySink:
    """A sink that keeps every record in lists (for scripts, demos and tests that post-process in memory)."""

    def __init__(self):
        self.fracture_snapshots: list[FractureSnapshot] = []
        self.fracture_balances: list[BalanceRecord] = []
        self.proppant_snapshots: list[ProppantSnapshot] = []
        self.proppant_balances: list[SolidBalanceRecord] = []

    def fracture_snapshot(self, record: FractureSnapshot) -> None:
        self.fracture_snapshots.append(record)

    def fracture_balance(self, record: BalanceRecord) -> None:
        self.fracture_balances.append(record)

    def proppant_snapshot(self, record: ProppantSnapshot) -> None:
        self.proppant_snapshots.append(record)

    def proppant_balance(self, record: SolidBalanceRecord) -> None:
        self.proppant_balances.append(record)
