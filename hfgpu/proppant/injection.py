"""Where parcels come from: the initial uniform suspension and the slurry inlets.

A slurry rate Q at slurry volume fraction c carries fluid (1 - c) Q and solids c Q (the paper's Eq. 7 source
Q(t) delta(x) is the fluid part here; the solids enter as parcels). Each inlet is a set of open cells (a
:class:`hfgpu.proppant.config.Port` mapped onto the grid) receiving its share of the rate. Parcels are emitted
with exactly the scheduled solid volume: an inlet keeps the solid volume not yet emitted and the diameter of the
next parcel, and emits parcels of ``particles_per_parcel`` particles while that volume covers the next one.

Screen-out: proppant cannot enter a cell packed beyond close packing (theta_cp, the singular limit of the
paper's interparticle stress, Eq. 16).
``emit`` takes the solid volume each cell can still take, ``room`` = theta_cp V_cell - (solid volume there,
the scatter of Eq. 38); a parcel goes to a random position of its inlet where its bilinear share (Eq. 37) fits
the room of every cell it touches, and a parcel that fits nowhere (after a few random positions) is held back:
its volume is added to ``screened_out`` (it counts as injected, never placed), so that
injected = in_domain + outflow + screened_out stays exact.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import SceneError
from ..records import GridFrame
from .config import Port, ProppantClass
from ..kernels.stencil_numpy import weights
from .interpolation import deposit_masks

PARCEL_KEYS = ("x", "z", "u", "v", "radius", "density", "particles", "state", "class_id")
#: Random positions in its inlet a parcel is tried at before it is held back (screen-out).
PLACEMENT_TRIES = 8


def port_cells(port: Port, frame: GridFrame, width: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(k, i) indices of the open cells a port covers (point: its cell; segment: the cells it crosses;
    annulus: the cells whose centres lie within [inner_radius, outer_radius] of the centre)."""
    nz, nx = width.shape
    if port.kind == "annulus":
        xc, zc = frame.centres(nz, nx)
        r = np.hypot(xc[None, :] - port.x, zc[:, None] - port.depth)
        k, i = np.nonzero((r >= port.inner_radius) & (r <= port.outer_radius))
    else:
        if port.kind == "point":
            xs, zs = np.array([port.x]), np.array([port.depth])
        else:
            length = math.hypot(port.x_end - port.x, port.depth_end - port.depth)
            s = np.linspace(0.0, 1.0, max(2, int(math.ceil(4 * length / min(frame.dx, frame.dz))) + 1))
            xs, zs = port.x + s * (port.x_end - port.x), port.depth + s * (port.depth_end - port.depth)
        i = np.clip(np.floor((xs - frame.x0) / frame.dx + 0.5).astype(int), 0, nx - 1)
        k = np.clip(np.floor((zs - frame.z0) / frame.dz + 0.5).astype(int), 0, nz - 1)
        k, i = np.unique(np.stack([k, i]), axis=1)
    keep = width[k, i] > 0.0
    return k[keep], i[keep]


def ports_to_cells(ports: tuple[Port, ...], frame: GridFrame, width: np.ndarray, key: str) -> list:
    """Cells of each port; a port that covers no open cell is a SceneError naming ``key[index]``."""
    cells = []
    for n, port in enumerate(ports):
        k, i = port_cells(port, frame, width)
        if k.size == 0:
            raise SceneError(f"{key}[{n}]", port, "this port covers no open cell of the grid")
        cells.append((k, i))
    return cells


def empty_batch() -> dict[str, np.ndarray]:
    """A parcel batch (dict of 1-D arrays in the shared layout) with no parcels."""
    return {k: np.zeros(0, dtype=np.int32 if k in ("state", "class_id") else float) for k in PARCEL_KEYS}


def make_batch(x, z, diameters, density, particles, class_id) -> dict[str, np.ndarray]:
    """Parcels at rest, suspended, of one class."""
    n = len(x)
    return dict(x=np.asarray(x, float), z=np.asarray(z, float), u=np.zeros(n), v=np.zeros(n),
                radius=0.5 * np.asarray(diameters, float), density=np.full(n, float(density)),
                particles=np.broadcast_to(np.asarray(particles, float), (n,)).copy(),
                state=np.zeros(n, np.int32), class_id=np.full(n, class_id, np.int32))


def concat_batches(batches: list[dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    if not batches:
        return empty_batch()
    return {k: np.concatenate([b[k] for b in batches]) for k in PARCEL_KEYS}


def batch_solid_volume(batch: dict[str, np.ndarray]) -> float:
    """Sum of particles x 4/3 pi r^3 over a batch [m^3]."""
    return float(np.sum(batch["particles"] * (4.0 / 3.0 * np.pi) * batch["radius"] ** 3))


def uniform_points(rng: np.random.Generator, frame: GridFrame, k: np.ndarray, i: np.ndarray,
                   cell: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points uniformly distributed in the cells ``(k[cell], i[cell])``."""
    x = frame.x0 + (i[cell] + rng.random(cell.size) - 0.5) * frame.dx
    z = frame.z0 + (k[cell] + rng.random(cell.size) - 0.5) * frame.dz
    return x, z


def lattice_shape(m: np.ndarray, dx: float, dz: float) -> tuple[np.ndarray, np.ndarray]:
    """(q_x, q_z): the lattice of about m points of a dx x dz cell with square-ish spacings, q_x =
    max(1, round(sqrt(m dx / dz))), q_z = max(1, round(m / q_x)); it holds q_x q_z points."""
    qx = np.maximum(1, np.rint(np.sqrt(m * dx / dz))).astype(int)
    return qx, np.maximum(1, np.rint(m / qx)).astype(int)


def initial_suspension(classes: tuple[ProppantClass, ...], frame: GridFrame, width: np.ndarray,
                       particles_per_parcel: list[float], rng: np.random.Generator,
                       placement: str = "lattice") -> dict[str, np.ndarray]:
    """Uniform suspension at t = 0: every open cell holds exactly theta_0 x V_cell of each class.

    Each cell gets about m = round(theta_0 V_cell / (particles_per_parcel E[V_p])) parcels (at least one) of
    each class, placed by ``placement``:

    * "lattice" (a quiet start): q_x x q_z parcels (:func:`lattice_shape`) at the centres of a regular q_x x q_z
      division of the cell, each carrying the same solid volume theta_0 V_cell / (q_x q_z) (its particle count
      set from its own drawn diameter). The bilinear deposit (Eq. 38) of a lattice whose spacing divides the
      cell is exactly uniform (the midpoint rule integrates the piecewise-linear kernel exactly), so theta_p
      starts without sampling noise: 16 random parcels a cell carry ~25 % noise in theta_p, where the real
      suspension's (~1e4 grains a cell) is ~1 %, and in a box several cells wide that noise drives a
      convection the real suspension does not have (docs/proppant-closures.md, "Quiet start").
    * "stratified": m parcels at uniform random x and depths stratified in m equal slices of the cell, all of
      a cell's parcels with the same particle count, set so that the cell's solid volume is exact.
    """
    k, i = np.nonzero(width > 0.0)
    volume = frame.dx * frame.dz * width[k, i]
    batches = []
    for c, cls in enumerate(classes):
        if cls.initial_volume_fraction <= 0.0:
            continue
        target = cls.initial_volume_fraction * volume
        counts = np.maximum(1, np.rint(target / (particles_per_parcel[c]
                                                 * cls.size.mean_particle_volume())).astype(int))
        if placement == "lattice":
            qx, qz = lattice_shape(counts, frame.dx, frame.dz)
            counts = qx * qz
        cell = np.repeat(np.arange(k.size), counts)
        rank = np.arange(cell.size) - np.repeat(np.cumsum(counts) - counts, counts)
        d = cls.size.sample(rng, cell.size)
        vp = np.pi / 6.0 * d**3
        if placement == "lattice":
            x = frame.x0 + (i[cell] - 0.5 + (rank % qx[cell] + 0.5) / qx[cell]) * frame.dx
            z = frame.z0 + (k[cell] - 0.5 + (rank // qx[cell] + 0.5) / qz[cell]) * frame.dz
            particles = (target / counts)[cell] / vp
        else:
            x, _ = uniform_points(rng, frame, k, i, cell)
            z = frame.z0 + (k[cell] - 0.5 + (rank + rng.random(cell.size)) / counts[cell]) * frame.dz
            particles = (target / np.bincount(cell, weights=vp, minlength=k.size))[cell]
        batches.append(make_batch(x, z, d, cls.density, particles, c))
    return concat_batches(batches)


@dataclass
class _Inlet:
    k: np.ndarray
    i: np.ndarray
    share: float
    owed: np.ndarray  # solid volume not yet emitted, per class [m^3]
    next_diameter: np.ndarray  # diameter of the next parcel, per class (NaN: not drawn yet)
    jet: str = "none"  # direction of the entering slurry (Port.jet)
    jet_area: float = math.inf  # cross-section normal to the jet [m^2]


def jet_area(k: np.ndarray, i: np.ndarray, jet: str, frame: GridFrame, width: np.ndarray) -> float:
    """Cross-section [m^2] an inlet's slurry enters through along ``jet``: over the grid lines normal to the
    jet that the inlet covers (rows for an x-jet, columns for a z-jet), the sum of the mean width of its cells
    on the line times the cell size across the jet (dz for an x-jet, dx for a z-jet); inf for "none"."""
    if jet == "none":
        return math.inf
    line, across = (k, frame.dz) if jet[1] == "x" else (i, frame.dx)
    _, index = np.unique(line, return_inverse=True)
    mean = np.bincount(index, weights=width[k, i]) / np.bincount(index)
    return float(np.sum(mean) * across)


class Injector:
    """Slurry inlets on the grid: fluid sources and parcels for a step (t0, t1].

    ``loadings(t)`` gives [(class index, slurry volume fraction)] at time t (from the schedule) and
    ``rate(t0, t1)`` the mean slurry rate over the step [m^3/s]; the solid volume entering over the step is
    c((t0+t1)/2) Q dt, exact while a step stays within one stage (the run loop ends steps at stage ends).
    ``split(t0, t1)`` (optional) gives each inlet's share of the rate over the step (summing to 1), in place of
    the ports' constant ``share``: the clusters of a stage, whose fluid split the wellbore node sets
    (hfgpu.stage_blocks.ClusterSplit); the solids follow the same split.
    """

    def __init__(self, ports: tuple[Port, ...], frame: GridFrame, width: np.ndarray,
                 classes: tuple[ProppantClass, ...], particles_per_parcel: list[float], rate, loadings,
                 rng: np.random.Generator, split=None):
        self.frame = frame
        self.shape = width.shape
        self.classes = classes
        self.particles_per_parcel = particles_per_parcel
        self.rate = rate
        self.loadings = loadings
        self.rng = rng
        self.split = split
        self.closed: set[int] = set()   # inlets found with every cell closed (warned once each)
        self.screened_out = 0.0  # solid volume held back at packed inlets [m^3]
        total = sum(p.share for p in ports)
        self.inlets = [_Inlet(k, i, p.share / total, np.zeros(len(classes)), np.full(len(classes), np.nan),
                              p.jet, jet_area(k, i, p.jet, frame, width))
                       for p, (k, i) in zip(ports, ports_to_cells(ports, frame, width, "geometry.inlets"))]

    def fluid_sources(self, t0: float, t1: float, width: np.ndarray | None = None) -> np.ndarray:
        """Fluid volume rate per cell (nz, nx) [m^3/s]: (1 - c) Q split over the inlets, and an inlet's part equally
        over its cells, those open in ``width`` (the step's) where given: an inlet whose cells have all closed
        (a starved cluster's perforation, hfgpu.coupled_stage) takes none, and a RuntimeWarning line says so."""
        self._set_shares(t0, t1)
        q = self.rate(t0, t1) * (1.0 - sum(f for _, f in self.loadings(0.5 * (t0 + t1))))
        return self._spread(q, width, t0)

    def slurry_sources(self, t0: float, t1: float) -> np.ndarray:
        """Slurry volume rate per cell (nz, nx) [m^3/s] (fluid plus solids)."""
        self._set_shares(t0, t1)
        return self._spread(self.rate(t0, t1))

    def jet_speed(self, inlet: _Inlet, t0: float, t1: float) -> float:
        """Speed [m/s] of an inlet's entering slurry: its share of the slurry rate over its jet cross-section
        (0 for "none")."""
        return self.rate(t0, t1) * inlet.share / inlet.jet_area

    def jet_momentum(self, t0: float, t1: float) -> tuple[np.ndarray, np.ndarray]:
        """Momentum the entering fluid carries into the fluid's face control volumes per unit fluid density
        [m^4/s^2] (the inlet source of the momentum balance, Eq. 8 / 26): on the downstream face of each cell of
        a jet inlet (the face in the jet's direction) its fluid rate (1 - c) Q_cell times the jet speed, signed
        along the axis; u faces (nz, nx+1), v faces (nz+1, nx). Zero for inlets without a jet."""
        self._set_shares(t0, t1)
        nz, nx = self.shape
        mx, mz = np.zeros((nz, nx + 1)), np.zeros((nz + 1, nx))
        fluid = 1.0 - sum(f for _, f in self.loadings(0.5 * (t0 + t1)))
        for inlet in self.inlets:
            if inlet.jet == "none":
                continue
            sign = 1.0 if inlet.jet[0] == "+" else -1.0
            m = sign * fluid * self.rate(t0, t1) * inlet.share / inlet.k.size * self.jet_speed(inlet, t0, t1)
            shift = 1 if sign > 0 else 0
            if inlet.jet[1] == "x":
                np.add.at(mx, (inlet.k, inlet.i + shift), m)
            else:
                np.add.at(mz, (inlet.k + shift, inlet.i), m)
        return mx, mz

    def _set_shares(self, t0: float, t1: float) -> None:
        """The inlets' shares over (t0, t1] from ``split`` (kept as they are without one)."""
        if self.split is not None:
            for inlet, share in zip(self.inlets, self.split(t0, t1)):
                inlet.share = float(share)

    def _spread(self, q: float, width: np.ndarray | None = None, t: float = 0.0) -> np.ndarray:
        out = np.zeros(self.shape)
        for n, inlet in enumerate(self.inlets):
            k, i = inlet.k, inlet.i
            if width is not None:
                open_cells = width[k, i] > 0.0
                k, i = k[open_cells], i[open_cells]
                if not k.size:
                    if q * inlet.share > 0.0 and n not in self.closed:
                        self.closed.add(n)
                        warnings.warn(f"inlet {n + 1}'s cells are closed at t = {t:.4g} s (on the proppant run's "
                                      f"clock): its share of the rate ({100 * inlet.share:.3g} %) does not enter "
                                      "the proppant grid while they stay closed", RuntimeWarning, stacklevel=4)
                    continue
            np.add.at(out, (k, i), q * inlet.share / k.size)
        return out

    def emit(self, t0: float, t1: float, room: np.ndarray | None = None,
             width: np.ndarray | None = None) -> dict[str, np.ndarray]:
        """Parcels entering during (t0, t1], placed uniformly at random in their inlet's cells, at rest (with the
        jet speed for a jet inlet).

        ``room`` (nz, nx): solid volume each cell can still take [m^3] (None: unlimited), on the grid of
        ``width`` (the step's width); a parcel is placed only where its bilinear share (Eq. 37) fits the room of
        every cell it lands on (up to PLACEMENT_TRIES random positions in its inlet), else it is held back
        (``screened_out``). ``room`` (float64) is reduced in place by the parcels placed."""
        self._set_shares(t0, t1)
        q = self.rate(t0, t1) * (t1 - t0)
        mask = None if room is None else deposit_masks(width)[0]
        batches = []
        for c, fraction in self.loadings(0.5 * (t0 + t1)):
            if fraction <= 0.0 or q <= 0.0:
                continue
            cls = self.classes[c]
            ppp = self.particles_per_parcel[c]
            for inlet in self.inlets:
                inlet.owed[c] += fraction * q * inlet.share
                d = self._draw(inlet, c, cls, ppp)
                if d.size:
                    x, z = uniform_points(self.rng, self.frame, inlet.k, inlet.i,
                                          self.rng.integers(0, inlet.k.size, d.size))
                    if room is not None:
                        placed = self._fit(inlet, x, z, ppp * np.pi / 6.0 * d**3, room, mask)
                        x, z, d = x[placed], z[placed], d[placed]
                    batch = make_batch(x, z, d, cls.density, ppp, c)
                    if inlet.jet != "none":  # the grains enter with the slurry's jet speed
                        sign = 1.0 if inlet.jet[0] == "+" else -1.0
                        batch["u" if inlet.jet[1] == "x" else "v"][:] = sign * self.jet_speed(inlet, t0, t1)
                    batches.append(batch)
        return concat_batches(batches)

    def _fit(self, inlet: _Inlet, x: np.ndarray, z: np.ndarray, volume: np.ndarray, room: np.ndarray,
             mask: np.ndarray) -> np.ndarray:
        """Which parcels (at x, z, of solid volume ``volume``) fit the room; moves (in place) those whose
        first position does not fit to another random position of the inlet, up to PLACEMENT_TRIES times,
        and adds the volume of the ones that never fit to ``screened_out``. ``room`` is reduced in place."""
        k, i, w = weights(x, z, self.frame, "cell", mask)
        need = np.zeros_like(room)
        np.add.at(need, (k, i), volume[:, None] * w)
        if np.all(need <= room):  # all fit at once (no screen-out near)
            room -= need
            return np.ones(x.size, dtype=bool)
        placed = np.zeros(x.size, dtype=bool)
        for p in range(x.size):
            kp, ip, wp = k[p], i[p], w[p]
            for _ in range(PLACEMENT_TRIES):
                if np.all(volume[p] * wp <= room[kp, ip]):
                    np.subtract.at(room, (kp, ip), volume[p] * wp)
                    placed[p] = True
                    break
                xs, zs = uniform_points(self.rng, self.frame, inlet.k, inlet.i,
                                        self.rng.integers(0, inlet.k.size, 1))
                x[p], z[p] = xs[0], zs[0]
                kp, ip, wp = (a[0] for a in weights(xs, zs, self.frame, "cell", mask))
            if not placed[p]:
                self.screened_out += float(volume[p])
        return placed

    def _draw(self, inlet: _Inlet, c: int, cls: ProppantClass, ppp: float) -> np.ndarray:
        """Diameters of the parcels whose volume the inlet owes, keeping the first one that does not fit."""
        if np.isnan(inlet.next_diameter[c]):
            inlet.next_diameter[c] = cls.size.sample(self.rng, 1)[0]
        parcel_volume = ppp * cls.size.mean_particle_volume()
        n = int(inlet.owed[c] / parcel_volume * 1.2) + 4
        d = np.concatenate([[inlet.next_diameter[c]], cls.size.sample(self.rng, n)])
        cumulative = np.cumsum(ppp * np.pi / 6.0 * d**3)
        while cumulative[-1] <= inlet.owed[c]:  # a rare run of small particles: draw more
            d = np.concatenate([d, cls.size.sample(self.rng, n)])
            cumulative = np.cumsum(ppp * np.pi / 6.0 * d**3)
        m = int(np.searchsorted(cumulative, inlet.owed[c], side="right"))
        inlet.owed[c] -= cumulative[m - 1] if m else 0.0
        inlet.next_diameter[c] = d[m]
        return d[:m]

    def owed_volume(self) -> float:
        """Solid volume scheduled but not yet emitted (less than one parcel per inlet and class) [m^3]."""
        return float(sum(inlet.owed.sum() for inlet in self.inlets))
