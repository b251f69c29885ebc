"""Validation of the MP-PIC bed against laws no one here wrote (issue 34, item 3): bed load over a settled bed
against Meyer-Peter & Mueller (1948), and the angle of repose of a pile poured in a slot. The set-ups and the
measurements are here; tests/proppant/test_bed_load.py and tests/proppant/test_repose.py assert them and
docs/validation.md reports them.

    python bench/bed_validation.py load [--shields 0.07 0.10 0.15 0.20] [--set 'bed_stress="overburden"']
    python bench/bed_validation.py repose [--end 8] [--rest 4] [--set bed_slope=true]   # poured, then at rest
    python bench/bed_validation.py collapse [--end 3] [--set KEY=VALUE]   # a packed column released

Every run is one process, NumPy backend, one core.

Bed load (``measure``): a slot 20 cm long, 4 cm high, gap 5 mm, 5 mm cells, proppant physics only; its bottom 4
rows packed with 0.3 mm sand (2650 kg/m^3) at theta_p 0.58 (a 4 x 4 lattice of parcels in each cell: a bed
without sampling noise); 2 cP fluid (1000 kg/m^3) entering through the left end above the bed (a source, no
jet) and leaving through the right end, at a mean speed U over the clear height. Measured over the middle half
of the slot (x in [L/4, 3L/4]), sampled every 50 ms over the window:

- the bed shear stress. The model resolves no velocity profile within a cell, neither across the gap nor
  above the bed: its bed shear stress is the surface stress of the gap-averaged (Brinkman) flow that the
  threshold of motion uses, tau_b = sqrt(12) mu U_f / w (hfgpu.kernels.closures.bed: the flow rises from 0
  at the bed to U_f over w / sqrt(12) = 1.4 mm), with U_f the mean x speed of the fluid in the first row of
  clear cells over the bed (two rows above the bed's top cell: the row between holds the grains that lie on
  the bed and is slowed by their drag). Two other readings are printed beside it: the face stress of plane
  Poiseuille flow at that speed, 6 mu U_f / w (1.73 x tau_b), and the grid's velocity gradient between the
  clear row and the grains' row, mu (U_f - U_layer) / dz (the 5 mm cells smear the layer: about 0.27 x tau_b);
- the Shields number theta = tau_b / ((rho_p - rho_f) g d);
- the solid flux per unit gap width, sum n_p V_p u_p / (L/2 w) over the parcels of the middle half, by owning
  row; the bed load is that of the bed's rows and the row of grains on it (rows >= TOP - 1), the total load
  adds the grains carried up into the clear flow; q* = q_s / sqrt((s - 1) g d^3);
- Meyer-Peter & Mueller (1948): q* = 8 (theta - 0.047)^1.5.

The 2 cP viscosity puts the model's critical Shields number (Soulsby & Whitehouse 1997, D* = 4.8: theta_cr
0.0495) at Meyer-Peter & Mueller's 0.047 and keeps the gap Reynolds number rho U_f w / mu of the runs at
700-1600 (laminar wall friction, the default). MPM was fitted to turbulent flume data of coarse grains
(0.4-29 mm): this compares the model with a law at the edge of that law's range.

Angle of repose (``pour``): a slot 16 cm long, 8 cm high, gap 5 mm, 5 mm cells, water (1 cP); slurry of 0.3 mm
sand (2650 kg/m^3) at volume fraction 0.2 enters through one cell at the top, in the middle (a source, no jet),
at 5e-7 m^3/s of sand; the fluid leaves through the top cells at both ends. The grains settle and build a pile
under the inlet. Its surface: in each column, the height where theta_p crosses half of close packing,
interpolated between cell centres from the bottom up (``surface``); its slope, a least-squares line through the
heights of each flank between 20 % and 80 % of the pile's height (``flank_angles``).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from hfgpu import load_scene
from hfgpu.kernels.closures import bed
from hfgpu.proppant.analysis import alternation
from hfgpu.proppant.parcels import Parcels
from hfgpu.proppant.engine_setup import proppant_engine_setup
from hfgpu.proppant.simulator import ProppantSimulation

# bed load
L, H, W, DZ, ROWS = 0.20, 0.04, 5e-3, 5e-3, 4
RHO_P, RHO_F, MU, D, THETA, G = 2650.0, 1000.0, 2e-3, 0.3e-3, 0.58, 9.81
TOP = round(H / DZ) - ROWS  # the bed's top row (rows counted from the top)
BUOYANT = (RHO_P - RHO_F) * G * D  # Shields stress scale [Pa]
Q_SCALE = np.sqrt((RHO_P / RHO_F - 1.0) * G * D ** 3)  # Einstein's flux scale [m^2/s]
# angle of repose
PILE_L, PILE_H = 0.16, 0.08
#: published angles of repose [deg] (docs/validation.md, "Angle of repose")
PUBLISHED = {"sand, Carter (1950)": 34.0, "rounded grains, Kleinhans et al. (2011)": 25.0,
             "angular grains, Kleinhans et al. (2011)": 40.0}


def mpm(theta):
    """Meyer-Peter & Mueller (1948): q* = 8 (theta - 0.047)^1.5, 0 below 0.047."""
    return 8.0 * np.maximum(np.asarray(theta, dtype=float) - 0.047, 0.0) ** 1.5


def speed_for(shields: float) -> float:
    """The mean clear-water speed whose Brinkman bed stress sqrt(12) mu U / w is ``shields``: the speed the run
    is set to (the flow over the bed comes out near it; the Shields number is read from the run)."""
    return shields * BUOYANT * W / (np.sqrt(12.0) * MU)


def mppic_lines(settings) -> str:
    """[mppic] lines from KEY=VALUE strings (VALUE as TOML)."""
    return "\n".join(f"{k.strip()} = {v.strip()}" for k, v in (s.split("=", 1) for s in settings))


def scene_head(end: float, fluid: str, kind: str, length: float, height: float, cell: float = DZ) -> str:
    """The scene text the three set-ups share: proppant only to ``end`` [s], seed 1, ``fluid`` ([fluid] lines),
    cells of ``cell`` [m], a ``kind`` ("slot" or "box") of ``length`` x ``height`` [m] and gap W."""
    return f"""
[run]
end_time = "{end} s"
physics = ["proppant"]
seed = 1
[fluid]
{fluid}
[mesh]
cell_size = "{cell} m"
[output]
every = "1 s"
[geometry]
kind = "{kind}"
length = "{length} m"
height = "{height} m"
""" + f'width = "{W} m"'


def sand_lines(extra: str) -> str:
    """The scene text the three set-ups end with: the sand (RHO_P, D) and the [mppic] table on the NumPy backend,
    with ``extra`` [mppic] lines."""
    return f"""
[[proppant]]
name = "sand"
density = "{RHO_P:g} kg/m**3"
diameter = "{D} m"
[mppic]
backend = "numpy"
{extra}
"""


def load_scene_text(speed: float, end: float, extra: str = "", length: float = L, viscosity: float = MU) -> str:
    """The bed-load slot of ``length`` [m] (default L) with fluid of ``viscosity`` [Pa s] (default MU) entering
    over the bed at mean ``speed`` [m/s] (``measure``; tests/proppant/test_bed_overburden.py uses it too)."""
    clear = H - ROWS * DZ
    fluid = f'viscosity = "{viscosity * 1e3:g} cP"\ndensity = "{RHO_F:g} kg/m**3"'
    return scene_head(end, fluid, "slot", length, H) + f"""
[[geometry.inlets]]
kind = "segment"
x = "1 mm"
depth = "1 mm"
x_end = "1 mm"
depth_end = "{clear - 1e-3} m"
[[geometry.outlets]]
kind = "segment"
x = "{length - 1e-3} m"
depth = "1 mm"
x_end = "{length - 1e-3} m"
depth_end = "{clear - 1e-3} m"
[injection]
schedule = [{{ until = "100 s", rate = "{speed * clear * W} m**3/s" }}]""" + sand_lines(extra)


def measure(shields: float, start: float = 0.5, end: float = 1.5, extra: str = "", every: float = 0.05,
            quiet: bool = False) -> dict:
    """Run the bed under the flow aimed at ``shields`` and average the figures of the module docstring over
    the samples in [start, end]; also the fastest grain along x and overall of the bed's rows at ``end``."""
    sim = ProppantSimulation(proppant_engine_setup(load_scene(load_scene_text(speed_for(shields), end, extra))))
    nx = round(L / DZ)
    q = 4
    x, z = np.meshgrid((np.arange(nx * q) + 0.5) * DZ / q, H - (np.arange(ROWS * q) + 0.5) * DZ / q)
    per = THETA * DZ * DZ * W / (np.pi / 6 * D ** 3) / q ** 2
    sim.set_parcels(Parcels.create(x.ravel(), z.ravel(), radius=D / 2, density=RHO_P, particles=per))
    sim.fluid = sim.solver.initial_state(sim._fluid_theta_p())  # the fluid's storage with the bed in place
    mid = slice(nx // 4 + 1, 3 * nx // 4 + 1)  # the x faces inside the middle half (u: nx + 1 faces a row)
    x0, x1 = L / 4, 3 * L / 4
    samples = []
    t_next = start
    while sim.time < end - 1e-9:
        sim.step(limit=min(end, t_next) - sim.time)
        if sim.time >= t_next - 1e-9:
            p = sim.parcels
            inside = (p.x >= x0) & (p.x < x1)
            volume = p.particles * np.pi / 6 * (2 * p.radius) ** 3
            row = np.floor((p.z[inside] - sim.grid.frame.z0) / DZ + 0.5).astype(int)
            by_row = np.bincount(row, volume[inside] * p.u[inside], minlength=round(H / DZ)) / ((x1 - x0) * W)
            samples.append((float(np.mean(sim.fluid.u[TOP - 2, mid])), float(np.mean(sim.fluid.u[TOP - 1, mid])),
                            *by_row))
            t_next += every
    u_f, u_layer, *by_row = np.mean(samples, axis=0)
    by_row = np.array(by_row) / Q_SCALE
    tau = float(bed.bed_shear_stress_numpy(u_f, W, RHO_F, MU, 0))
    theta = tau / BUOYANT
    p = sim.parcels
    k = np.floor((p.z - sim.grid.frame.z0) / DZ + 0.5).astype(int)
    r = {"shields_aimed": shields, "U": speed_for(shields), "U_f": u_f, "Re": RHO_F * u_f * W / MU,
         "tau_b": tau, "tau_poiseuille": 6 * MU * u_f / W, "tau_grid": MU * (u_f - u_layer) / DZ,
         "theta": theta, "theta_cr": float(bed.critical_shields_number_numpy(D, RHO_P, RHO_F, MU, G)),
         "q_bed": float(by_row[TOP - 1:].sum()), "q_total": float(by_row.sum()), "mpm": float(mpm(theta)),
         "bed_u_max": float(np.abs(p.u[k >= TOP]).max()), "bed_speed_max": float(np.hypot(p.u, p.v)[k >= TOP].max()),
         "rows": by_row[TOP - 2:], "samples": len(samples)}
    r["ratio_bed"] = r["q_bed"] / r["mpm"] if r["mpm"] > 0 else np.inf
    r["ratio_total"] = r["q_total"] / r["mpm"] if r["mpm"] > 0 else np.inf
    if not quiet:
        print(f"aimed theta {shields:.3f}: U_f {u_f:.4f} m/s (Re {r['Re']:.0f}), tau_b {tau:.4f} Pa "
              f"(Poiseuille {r['tau_poiseuille']:.4f}, grid {r['tau_grid']:.4f}), theta {theta:.4f} "
              f"(theta_cr {r['theta_cr']:.4f}); q* bed {r['q_bed']:.4g}, total {r['q_total']:.4g}, MPM "
              f"{r['mpm']:.4g}: ratio bed {r['ratio_bed']:.3g}, total {r['ratio_total']:.3g}; q* by row "
              f"{TOP - 2}..{round(H / DZ) - 1}: " + " ".join(f"{v:.3g}" for v in r["rows"])
              + f"; bed rows at {end:g} s: max |u| {r['bed_u_max']:.3g} m/s, max speed {r['bed_speed_max']:.3g} m/s",
              flush=True)
        theta_p = sim.moments.volume_fraction
        for row in range(TOP - 2, round(H / DZ)):
            own = k == row
            print(f"    at {end:g} s, row {row}{' (bed top)' if row == TOP else ''}: fluid u over the middle half "
                  f"mean {np.mean(sim.fluid.u[row, mid]):.3g} m/s, max |u| {np.abs(sim.fluid.u[row, mid]).max():.3g}; "
                  f"theta_p {np.mean(theta_p[row, nx // 4:3 * nx // 4]):.3f}; {own.sum()} parcels, fastest "
                  f"{np.abs(p.u[own]).max() if own.any() else 0.0:.3g} m/s along x", flush=True)
    return r


def pile_scene_text(end: float, rest: float = 0.0, solid_rate: float = 5e-7, extra: str = "",
                    cell: float = DZ) -> str:
    rest_line = f', {{ until = "{end + rest} s", rate = "0 m**3/s" }}' if rest > 0.0 else ""
    return scene_head(end + rest, 'viscosity = "1 cP"', "slot", PILE_L, PILE_H, cell) + f"""
[[geometry.inlets]]
kind = "point"
x = "{PILE_L / 2 + cell / 2} m"
depth = "{cell / 2} m"
[[geometry.outlets]]
kind = "point"
x = "{cell / 2} m"
depth = "{cell / 2} m"
[[geometry.outlets]]
kind = "point"
x = "{PILE_L - cell / 2} m"
depth = "{cell / 2} m"
[injection]
schedule = [{{ until = "{end} s", rate = "{solid_rate / 0.2} m**3/s", proppant = "sand", volume_fraction = 0.2 }}\
{rest_line}]""" + sand_lines(extra)


def surface(theta: np.ndarray, level: float, dz: float = DZ) -> np.ndarray:
    """Height [m] above the floor where each column's theta_p crosses ``level``: the first cell from the bottom
    up below it, interpolated linearly with the cell under it between their centres (0 where the bottom cell is
    below it, the column's height where no cell is)."""
    nz, nx = theta.shape
    heights = np.zeros(nx)
    for i in range(nx):
        col = theta[::-1, i]  # bottom up: col[j]'s centre is (j + 1/2) dz above the floor
        if col[0] < level:
            continue
        below = np.nonzero(col < level)[0]
        if below.size == 0:
            heights[i] = nz * dz
            continue
        j = below[0]
        heights[i] = (j - 0.5) * dz + dz * (col[j - 1] - level) / (col[j - 1] - col[j])
    return heights


def flank_angles(heights: np.ndarray, dx: float = DZ) -> tuple[float, float, float]:
    """(peak height [m], left angle, right angle [deg]): least-squares slopes of each flank's surface between
    20 % and 80 % of the peak height, the end columns left out; 90 deg where a flank has fewer than two such
    columns (a cliff within one cell)."""
    x = (np.arange(heights.size) + 0.5) * dx
    peak = int(np.argmax(heights))
    top = float(heights[peak])
    angles = []
    for side in (slice(1, peak), slice(peak + 1, heights.size - 1)):
        xs, hs = x[side], heights[side]
        use = (hs > 0.2 * top) & (hs < 0.8 * top)
        if use.sum() < 2:
            angles.append(90.0)
            continue
        angles.append(float(np.degrees(np.arctan(abs(np.polyfit(xs[use], hs[use], 1)[0])))))
    return top, angles[0], angles[1]


def pour(end: float = 8.0, extra: str = "", quiet: bool = False, rest: float = 0.0, cell: float = DZ) -> dict:
    """Pour the pile for ``end`` seconds on cells of ``cell`` [m] and let it rest ``rest`` seconds more (no
    flow); its surface, flank angles and the fastest grain in it at the end."""
    sim = ProppantSimulation(proppant_engine_setup(load_scene(pile_scene_text(end, rest, extra=extra, cell=cell))))
    end = end + rest
    while sim.time < end - 1e-9:
        sim.step(limit=end - sim.time)
    theta = sim.moments.volume_fraction
    heights = surface(theta, 0.5 * sim.params.theta_cp, cell)
    top, left, right = flank_angles(heights, cell)
    p = sim.parcels
    in_pile = p.z > PILE_H - top
    r = {"end": end, "parcels": p.n, "peak": top, "left": left, "right": right, "angle": 0.5 * (left + right),
         "heights": heights, "pile_speed_max": float(np.hypot(p.u, p.v)[in_pile].max()) if in_pile.any() else 0.0,
         "alternation": alternation(theta)}
    if not quiet:
        print(f"pile at {end:g} s ({p.n} parcels): surface heights [mm] " + " ".join(f"{1e3 * h:.1f}" for h in heights))
        print(f"peak {1e3 * top:.1f} mm, flank angles {left:.1f} / {right:.1f} deg (mean {r['angle']:.1f}); "
              f"fastest grain in the pile {r['pile_speed_max']:.3g} m/s; published: "
              + ", ".join(f"{k} {v:g} deg" for k, v in PUBLISHED.items()), flush=True)
        print_packing(theta, r["alternation"])
    return r


def print_packing(theta: np.ndarray, counted: tuple[int, float]) -> None:
    print(f"packing: theta_p up to {theta.max():.3f}; of the {counted[0]} dense cells with dense neighbours along x, "
          f"{100 * counted[1]:.0f} % a local extreme along x by > 0.05", flush=True)


def column_scene_text(end: float, extra: str = "") -> str:
    return scene_head(end, 'viscosity = "1 cP"', "box", PILE_L, PILE_H) + sand_lines(extra)


def collapse(end: float = 3.0, columns: int = 4, rows: int = 12, extra: str = "", quiet: bool = False,
             since: float | None = None) -> dict:
    """Release a packed column of sand (theta_p 0.58, ``columns`` cells wide, ``rows`` cells high, a 4 x 4
    lattice of parcels a cell) standing on the floor in the middle of the closed slot of ``pour``, in water at
    rest, and measure its surface and flank angles at ``end`` as ``pour`` does; with ``since``, also how far the
    surface moved from ``since`` to ``end`` ("moved", the largest change of a column's height [m])."""
    sim = ProppantSimulation(proppant_engine_setup(load_scene(column_scene_text(end, extra))))
    q = 4
    nx = round(PILE_L / DZ)
    left = (nx - columns) // 2 * DZ
    x, z = np.meshgrid(left + (np.arange(columns * q) + 0.5) * DZ / q, PILE_H - (np.arange(rows * q) + 0.5) * DZ / q)
    per = THETA * DZ * DZ * W / (np.pi / 6 * D ** 3) / q ** 2
    sim.set_parcels(Parcels.create(x.ravel(), z.ravel(), radius=D / 2, density=RHO_P, particles=per))
    sim.fluid = sim.solver.initial_state(sim._fluid_theta_p())
    before = surface(sim.moments.volume_fraction, 0.5 * sim.params.theta_cp)

    def heights_at(stop: float) -> np.ndarray:
        while sim.time < stop - 1e-9:
            sim.step(limit=stop - sim.time)
        return surface(sim.moments.volume_fraction, 0.5 * sim.params.theta_cp)

    earlier = heights_at(since) if since is not None else before
    heights = heights_at(end)
    top, left_angle, right_angle = flank_angles(heights)
    p = sim.parcels
    r = {"end": end, "peak": top, "left": left_angle, "right": right_angle, "angle": 0.5 * (left_angle + right_angle),
         "heights": heights, "before": before, "speed_max": float(np.hypot(p.u, p.v).max()),
         "moved": float(np.abs(heights - earlier).max()), "alternation": alternation(sim.moments.volume_fraction)}
    if not quiet:
        print("column at 0 s: surface heights [mm] " + " ".join(f"{1e3 * h:.1f}" for h in before))
        print(f"column at {end:g} s: surface heights [mm] " + " ".join(f"{1e3 * h:.1f}" for h in heights))
        print(f"peak {1e3 * top:.1f} mm, flank angles {left_angle:.1f} / {right_angle:.1f} deg; fastest grain "
              f"{r['speed_max']:.3g} m/s" + (f"; surface moved {1e3 * r['moved']:.2f} mm since {since:g} s"
                                             if since is not None else ""), flush=True)
        print_packing(sim.moments.volume_fraction, r["alternation"])
    return r


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("case", choices=("load", "repose", "collapse"))
    parser.add_argument("--shields", type=float, nargs="+", default=[0.07, 0.10, 0.15, 0.20])
    parser.add_argument("--start", type=float, default=0.5)
    parser.add_argument("--end", type=float, default=None)
    parser.add_argument("--rest", type=float, default=0.0, help="repose: seconds at rest after the pour")
    parser.add_argument("--cell", type=float, default=DZ, help="repose: cell size [m]")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="an [mppic] key")
    args = parser.parse_args()
    extra = mppic_lines(args.set)
    t0 = time.perf_counter()
    if args.case == "load":
        for s in args.shields:
            measure(s, args.start, args.end or 1.5, extra)
    elif args.case == "repose":
        pour(args.end or 8.0, extra, rest=args.rest, cell=args.cell)
    else:
        collapse(args.end or 3.0, extra=extra)
    print(f"wall {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
