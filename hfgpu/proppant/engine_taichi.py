"""The Taichi particle engine: the parcels and the particle phase's grid fields live in Taichi ndarrays where
the kernels run (the CPU, or a CUDA GPU), allocated once (the parcel arrays again when the capacity grows,
geometrically) and reused; a particle sub-step is one kernel launch (hfgpu.kernels.engine).

What crosses between host and device (docs/engine.md): per fluid step, the fluid's u, v, p in, and the face
forces, cell moments and a few scalars out (grid-sized: the fluid is solved on the host); the inlets' new
parcels in; the parcels out only for snapshots and checkpoints. A retry of a step costs no copy: the sort at
the start of a step writes the work buffer from the accepted one, which stays as it was until ``commit``.
"""

from __future__ import annotations

import numpy as np

from ..kernels import layout as L
from .engine_seam import SubLoop
from .engine_numpy import bad_parcel
from .grid import StaggeredGrid
from .params import MppicParams
from .parcels import Parcels
from .particle_ops_numpy import CellMoments, check_fluid

MIN_CAPACITY = 1024


class TaichiEngine:
    """See hfgpu.proppant.engine_seam for the seam. Deposits (scatter, exchange): on the CPU each of up to
    ``PRIVATE_COPIES`` parcel blocks sums into its own grid copy without atomics (at most ``PRIVATE_BYTES`` of
    copies in all; a block has at least ``PARCELS_PER_COPY`` parcels and at least half as many parcels as the
    grid has cells, since each copy costs a zeroing and a summing pass over the grid and each parcel about four
    cells' worth of deposits), and the parcels are re-sorted with a stable
    (serial) scatter; on CUDA, blocks of CHUNK parcels add into one grid with atomics, and the sort's scatter is
    parallel. ``private`` forces either deposit (tests run the GPU's on the CPU), ``stable_sort`` either sort."""

    name = "taichi"
    PRIVATE_COPIES = 16
    PRIVATE_BYTES = 64 * 2 ** 20
    PARCELS_PER_COPY = 1024

    def __init__(self, grid: StaggeredGrid, params: MppicParams, fluid_density: float, fluid_viscosity: float,
                 gravity: float, outlets: np.ndarray, arch: str | None = None, private: bool | None = None):
        from ..kernels.runtime import init, thread_count, ti

        self.arch = init(arch)
        self.threads = thread_count()
        from ..kernels import engine as ke

        self._ti, self._k = ti, ke
        self.private = self.arch == "cpu" if private is None else private
        self.stable_sort = self.private  # the sort's scatter in parcel order (serial), else with atomics
        self.copies_limit = min(self.PRIVATE_COPIES, 2 * (self.threads or 1))
        self.params = params
        self.grid = grid
        self.outlets = np.ascontiguousarray(outlets, dtype=np.int32)
        nz, nx = grid.shape
        f64, i32 = ti.f64, ti.i32
        self._cells = ti.ndarray(f64, (L.CELL_CHANNELS, nz, nx))
        self._xf = ti.ndarray(f64, (L.FACE_CHANNELS, nz, nx + 1))
        self._zf = ti.ndarray(f64, (L.FACE_CHANNELS, nz + 1, nx))
        self._flags = ti.ndarray(i32, (nz, nx))
        self._counts = ti.ndarray(ti.i64, ((2 * nz + 2) * (2 * nx + 2) + 1,))
        self._stats = ti.ndarray(f64, (L.STAT_COUNT,))
        copies = self.PRIVATE_COPIES if self.private else 1
        self._cd = ti.ndarray(f64, (copies, nz, nx, L.MOMENT_COUNT))
        self._xd = ti.ndarray(f64, (copies, nz, nx + 1, 2))
        self._zd = ti.ndarray(f64, (copies, nz + 1, nx, 2))
        self._params = ti.ndarray(f64, (L.PARAM_COUNT,))
        self._params.from_numpy(param_vector(params, grid, fluid_density, fluid_viscosity, gravity))
        self.host_cells = np.zeros((len(ke.CELL_OUT), nz, nx))  # the channels of CELL_OUT, FACE_OUT
        self.host_xf = np.zeros((len(ke.FACE_OUT), nz, nx + 1))
        self.host_zf = np.zeros((len(ke.FACE_OUT), nz + 1, nx))
        self.host_stats = np.zeros(L.STAT_COUNT)
        self.launches = 0  # kernel launches so far
        self.transfers = 0  # host arrays handed to kernels so far (each crosses to and from a GPU)
        self.transfer_bytes = 0
        self.capacity = 0
        self.n = 0  # parcels in the current buffer, GONE ones included until the next sort
        self._accepted_n = 0
        self._buffers: list = []
        self._accepted = 0  # the buffer of the accepted parcels
        self._current = 0  # the buffer operated on: the accepted one between steps, the other one in a step
        self._fresh = False  # host_cells / ST_SPEED / ST_VOLUME hold the moments of the parcels as they are
        self._left = 0  # parcels of the current buffer that left through outlets (GONE)
        self._grow(MIN_CAPACITY)
        self.set_grid(grid)

    # -- buffers ----------------------------------------------------------------------------------------

    def _grow(self, needed: int) -> None:
        """Capacity for ``needed`` parcels: twice the old one or more, the parcels kept."""
        if needed <= self.capacity:
            return
        ti, capacity = self._ti, max(needed, 2 * self.capacity, MIN_CAPACITY)
        buffers = [(ti.ndarray(ti.f64, (L.PARCEL_ROWS, capacity)), ti.ndarray(ti.i32, (L.STATE_ROWS, capacity)))
                   for _ in range(2)]
        for old, new in zip(self._buffers, buffers):
            self._launch(self._k.copy_parcels, *old, *new, max(self.n, self._accepted_n))
        self._buffers = buffers
        self._work_rows = ti.ndarray(ti.f64, (L.WORK_ROWS, capacity))
        self._keys = ti.ndarray(ti.i64, (capacity,))
        blocks = max(self.PRIVATE_COPIES, -(-capacity // 64))
        self._block_sums = ti.ndarray(ti.f64, (3, blocks))
        self.capacity = capacity

    def _launch(self, kernel, *args) -> None:
        """Launch ``kernel``, counting the launch and the host (NumPy) arrays among its arguments."""
        kernel(*args)
        self.launches += 1
        for a in args:
            if isinstance(a, np.ndarray):
                self.transfers += 1
                self.transfer_bytes += a.nbytes

    def _blocks(self) -> tuple[int, int]:
        """(blocks, copies) of a deposit over the current parcels."""
        n = self.n
        if not self.private:
            return max(1, -(-n // 64)), 1
        nz, nx = self.grid.shape
        fit = max(1, self.PRIVATE_BYTES // (8 * (nz + 1) * (nx + 1) * L.MOMENT_COUNT))
        blocks = max(1, min(self.copies_limit, fit, n // max(self.PARCELS_PER_COPY, nz * nx // 2)))
        return blocks, blocks

    def set_grid(self, grid: StaggeredGrid) -> None:
        """A new width field on the same frame (masks, face widths, flags)."""
        self.grid = grid
        width = np.ascontiguousarray(grid.width, dtype=np.float64)
        self._launch(self._k.set_grid, width, self.outlets, self._cells, self._xf, self._zf, self._flags,
                     self._params)
        self._fresh = False

    def append(self, batch: Parcels) -> None:
        """Add parcels at the end (into the work buffer during a step)."""
        m = batch.n
        if m == 0:
            return
        self._grow(self.n + m)
        values = np.stack([getattr(batch, name) for name in L.FLOAT_FIELDS])
        ints = np.stack([getattr(batch, name) for name in L.INT_FIELDS]).astype(np.int32)
        self._launch(self._k.append, *self._buffers[self._current], self.n, values, ints)
        self.n += m
        if self._current == self._accepted:
            self._accepted_n = self.n
        self._fresh = False

    @property
    def live(self) -> int:
        """Parcels in the domain (those that left in the last sub-loop not counted)."""
        return self.n - self._left

    def parcels(self) -> Parcels:
        """A host copy of the parcels (those that left dropped)."""
        values = np.empty((L.PARCEL_ROWS, self.n))
        ints = np.empty((L.STATE_ROWS, self.n), dtype=np.int32)
        if self.n:
            self._launch(self._k.read_parcels, *self._buffers[self._current], values, ints)
        keep = ints[L.STATE] != L.GONE
        return Parcels(**{name: values[row][keep] for row, name in enumerate(L.FLOAT_FIELDS)},
                       **{name: ints[row][keep] for row, name in enumerate(L.INT_FIELDS)})

    def set_parcels(self, parcels: Parcels) -> None:
        """Replace the parcels (accepted state)."""
        self._current = self._accepted
        self.n = self._accepted_n = self._left = 0
        self.append(parcels)

    # -- a fluid step -----------------------------------------------------------------------------------

    def begin_step(self, u: np.ndarray, v: np.ndarray, p: np.ndarray) -> None:
        """Sort the accepted parcels by cell into the work buffer, dropping those that left; load the fluid."""
        check_fluid(self.grid.width, u, v, p)
        self._current = 1 - self._accepted
        self._launch(self._k.begin_step, *self._buffers[self._accepted], *self._buffers[self._current],
                     self._keys, self._counts, self._accepted_n, self.stable_sort, as_f64(u), as_f64(v), as_f64(p),
                     self._cells, self._xf, self._zf, self._params, self._stats)
        self._launch(self._k.read_stats, self._stats, self.host_stats)
        self.n = int(self.host_stats[L.ST_LIVE])
        self._left = 0
        self._fresh = False

    def commit(self) -> None:
        """Accept the work parcels."""
        self._accepted = self._current
        self._accepted_n = self.n

    def substeps(self, dt: float, count: int, t0: float) -> SubLoop:
        """``count`` sub-steps of dt / count (one launch each), then the reports read back."""
        h = dt / count
        blocks, copies = self._blocks()
        for s in range(count):
            self._launch(self._k.substep, *self._buffers[self._current], self._work_rows, self._cells, self._xf,
                         self._zf, self._flags, self._cd, self._xd, self._zd, self._block_sums, self._params,
                         self._stats, self.n, blocks, copies, self.private, h, s, float(count))
        self._fresh = False
        self._launch(self._k.read_faces, self._xf, self._zf, self._stats, self.host_xf, self.host_zf,
                     self.host_stats)
        st = self.host_stats
        self._left = int(st[L.ST_LEFT])
        if st[L.ST_BAD_STEP] < L.NO_BAD:
            j = int(st[L.ST_BAD_PARCEL])
            parcel = self.parcels_at(j)
            raise bad_parcel(j, parcel[L.X], parcel[L.Z], self.grid.frame, t0 + (st[L.ST_BAD_STEP] + 1) * h)
        x, z = (dict(zip(self._k.FACE_OUT, faces.copy())) for faces in (self.host_xf, self.host_zf))
        return SubLoop(x["force"], z["force"], x["beta"], z["beta"], float(st[L.ST_OUTFLOW]))

    def parcels_at(self, j: int) -> np.ndarray:
        """The float rows of parcel j (an error message's cell)."""
        values = np.empty((L.PARCEL_ROWS, j + 1))
        self._launch(self._k.read_parcels, *self._buffers[self._current], values,
                     np.empty((L.STATE_ROWS, j + 1), dtype=np.int32))
        return values[:, j]

    def _refresh(self) -> None:
        """The moments of the parcels as they are, read back (once per change of the parcels or the grid)."""
        if self._fresh:
            return
        blocks, copies = self._blocks()
        self._launch(self._k.moments, *self._buffers[self._current], self._cells, self._flags, self._cd,
                     self._block_sums, self._params, self._stats, self.n, blocks, copies, self.private)
        self._launch(self._k.read_cells, self._cells, self._stats, self.host_cells, self.host_stats)
        self._fresh = True

    def moments(self) -> CellMoments:
        """Cell moments of the parcels (Eq. 38), host copies."""
        self._refresh()
        return CellMoments(**dict(zip(self._k.CELL_OUT, self.host_cells.copy())))

    def max_speed(self) -> float:
        """max |u| + |v| over the parcels."""
        self._refresh()
        return float(self.host_stats[L.ST_SPEED])

    def solid_volume(self) -> float:
        """Solid volume of the parcels [m^3], summed in block order."""
        self._refresh()
        return float(self.host_stats[L.ST_VOLUME])

    def device_bytes(self) -> tuple[int, int]:
        """(bytes per parcel of capacity, bytes in all) that the engine's arrays hold on the device."""
        per_parcel = 2 * (8 * L.PARCEL_ROWS + 4 * L.STATE_ROWS) + 8 * L.WORK_ROWS + 8
        grid = sum(8 * int(np.prod(a.shape)) for a in (self._cells, self._xf, self._zf, self._cd, self._xd, self._zd,
                                                      self._block_sums, self._params, self._stats))
        grid += 4 * int(np.prod(self._flags.shape)) + 8 * int(np.prod(self._counts.shape))
        return per_parcel, per_parcel * self.capacity + grid


def as_f64(a: np.ndarray) -> np.ndarray:
    """A contiguous float64 view or copy."""
    return np.ascontiguousarray(a, dtype=np.float64)


def param_vector(params: MppicParams, grid: StaggeredGrid, rho_f: float, mu_f: float, gravity: float) -> np.ndarray:
    """The run constants PR, slot by slot by their names in kernels.layout PARAMS: an attribute of ``params``
    (MppicParams) by its name, else the run's value of that name (the grid frame's x0, z0, dx, dz; rho_f, mu_f,
    gravity); ValueError for a name that is neither (or both)."""
    frame = grid.frame
    run = {"x0": frame.x0, "z0": frame.z0, "dx": frame.dx, "dz": frame.dz, "rho_f": rho_f, "mu_f": mu_f,
           "gravity": gravity}
    out = np.zeros(L.PARAM_COUNT)
    for slot, name in enumerate(L.PARAMS):
        if (name in run) == hasattr(params, name):
            raise ValueError(f"param_vector: PARAMS name {name!r} is {'both' if name in run else 'neither'} an "
                             f"attribute of MppicParams {'and' if name in run else 'nor'} a run value {sorted(run)}")
        out[slot] = float(run[name] if name in run else getattr(params, name))
    return out
