"""What ``hfgpu check`` expects of a fracture scene before it runs: the fracture's size and opening from a closed
form, the run's work (fracture cells, proppant steps, parcels), and the warnings these lead to.

The fracture is Dontsov's (2016) radial solution (:func:`hfgpu.reference.radial.dontsov_radial`, toughness,
viscosity and Carter leak-off) with the rock at the injection depth (E' = E / (1 - nu^2), K' = 4 (2/pi)^1/2 K_Ic,
C' = 2 C_L of that layer), mu' = 12 mu and the mean pumped rate Q = pumped volume / pumping time (over N for a
stage of N clusters, ``[completion]``: each fracture an equal share), at the end of pumping and when the first
proppant is pumped. Layers are ignored: a height-contained fracture of the same volume
is longer and about as wide, so these are scales, not predictions.

The work: the fracture grid's cells pi R^2 / (dx dz) at the end of pumping; the proppant fluid steps (end time -
first proppant) / dt, dt = min(``[mppic] dt_max``, the fluid Courant step at the perforation c_max d / u with u =
Q / (4 d w(0)), the rate leaving the perforated cell of side d through its four faces, w(0) when the first
proppant is pumped); at most ``max_parcels`` parcels; their product with ``particle_substeps``, the parcel
updates, is what the particle engine's speed multiplies (docs/benchmarks.md measures both engines).

Closure after shut-in (``closure_after``): Nolte's (1979) relation between the efficiency at the end of pumping
and the G-function at closure, eta = G_c / (4 g_0 / pi + G_c) (hfgpu.fracture.falloff, alpha = 1/2: Carter-
dominated area growth, the bound that closes soonest), solved for the time after shut-in at which G(dt_D) = G_c:
dt_c = t_p dt_D. None without leak-off (the fracture never closes). Nolte's relation holds the area at its
value at shut-in. A fracture that keeps spreading after shut-in (a short, fast injection: a pulse) stops where
the first of two things stops it: toughness, at the penny crack holding its volume V, R_K = (3 E' V / (8 sqrt(pi)
K_Ic))^(2/5) (Sneddon 1946), or leak-off, at the viscous pulse's arrest radius R_a (Moeri & Lecampion 2022;
hfgpu.reference.radial.leakoff_arrest_radius). Where that radius R_s is more than twice the radius at shut-in,
the closure time is instead the time Carter's law takes to leak the volume stored at shut-in over that area
(``closure_basis`` "arrest"): dt_c = (eta V / (2 C' pi R_s^2))^2.

Warnings (:func:`warnings`):

* a proppant whose largest grain x ``bridging_factor`` exceeds the expected opening at the perforation when it
  is first pumped: it bridges there (a screen-out at the inlet) unless the fracture is wider;
* a fracture that reaches fewer than :data:`MIN_CELLS_RADIUS` cells from the perforation by the end of pumping
  (the rate is too low for the leak-off, or the cells too large): the grid does not resolve it;
* a fluid efficiency below :data:`MIN_EFFICIENCY` at the end of pumping: leak-off takes nearly all the fluid;
* a shut-in longer than :data:`LONG_SHUT_IN` times the pumping time (with the expected closure time).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from .units import display_text, format_number

#: Cells from the perforation the fracture should reach by the end of pumping.
MIN_CELLS_RADIUS = 3
#: Fluid efficiency (volume in the fracture / pumped) below which leak-off is said to dominate.
MIN_EFFICIENCY = 0.05
#: Significant figures of the scales shown (estimates, not predictions).
DIGITS = 3
#: K' [Pa m^1/2] used for a rock without toughness (the closed form needs K' > 0; the viscosity-storage radius of
#: a 0.1 m^3/s, 12 cP, E' 20 GPa fracture at 600 s is then within 0.2 % of Savitski & Detournay's 126.4 m).
MIN_TOUGHNESS = 1e3
#: A shut-in longer than this many times the pumping time is warned of.
LONG_SHUT_IN = 1e6
#: Area-growth exponent of the closure estimate (Carter-dominated growth).
CLOSURE_ALPHA = 0.5


@dataclass(frozen=True)
class Estimate:
    """Scales of a run before it runs (SI): the radial fracture at the end of pumping (``radius`` R [m],
    ``efficiency``, ``opening`` w(0) [m]); the opening at the perforation when each proppant is first pumped
    (``first_openings``: name -> (time [s], w(0) [m])); ``cells`` of the fracture grid; ``proppant_steps``,
    ``parcels`` (an upper bound, None when set per cell) and ``parcel_updates`` (None without both);
    ``closure_after`` [s] after shut-in (None without leak-off) and its ``closure_basis``, "nolte" or "arrest"
    (module docstring)."""

    pumping_time: float
    rate: float
    radius: float
    efficiency: float
    opening: float
    first_openings: dict[str, tuple[float, float]]
    cells: float
    closure_after: float | None
    closure_basis: str
    proppant_steps: int | None
    parcels: int | None
    parcel_updates: float | None


def pumped(schedule: Any) -> tuple[float, float]:
    """(pumping time [s] to the end of the last stage with rate > 0, pumped volume [m^3]); (0, 0) without one."""
    end = schedule.pump_end or 0.0
    return end, schedule.volume(end)


def first_pumped(schedule: Any) -> dict[str, float]:
    """{proppant name: the time its first stage starts [s]}."""
    out: dict[str, float] = {}
    start = 0.0
    for stage in schedule.stages:
        if stage.proppant is not None and stage.rate > 0.0 and stage.proppant not in out:
            out[stage.proppant] = start
        start = stage.until
    return out


def estimate(scene: Any) -> Estimate | None:
    """The module docstring's scales of a scene with a fracture and a pumped schedule (None otherwise)."""
    if scene.rock is None or scene.injection is None or scene.fluid is None or not scene.has("fracture"):
        return None
    t_pump, volume = pumped(scene.injection.schedule)
    volume /= _clusters(scene)   # a stage's clusters: each fracture an equal share
    if t_pump <= 0.0 or volume <= 0.0:
        return None
    from .reference.radial import dontsov_radial, scaled_parameters  # a fracture scene's: a proppant run needs none
    rock, depth = scene.rock, scene.injection.depth
    groups = scaled_parameters(rock.youngs_modulus, rock.poisson_ratio, float(rock.toughness_at([depth])[0]),
                               scene.fluid.viscosity, float(rock.leakoff_at([depth])[0]))
    rate = volume / t_pump
    toughness = max(groups.K_prime, MIN_TOUGHNESS)

    def radial(t: float):
        return dontsov_radial(groups.E_prime, toughness, groups.mu_prime, groups.C_prime, rate, t)

    end = radial(t_pump)
    radius = float(end.R[-1])
    if not all(math.isfinite(float(v[-1])) for v in (end.R, end.w0, end.efficiency)):
        return None   # the closed form overflows (an absurd modulus or rate): nothing to expect
    first: dict[str, tuple[float, float]] = {}
    for name, t in first_pumped(scene.injection.schedule).items():
        t_seen = max(t, 1e-3 * t_pump)  # sand from the first second: the opening a moment after it starts
        first[name] = (t, float(radial(t_seen).w0[-1]))
    cells = math.pi * radius**2 / (scene.mesh.dx * scene.mesh.dz)
    closure, basis = None, "nolte"
    if groups.C_prime > 0.0:
        stops = arrest_radius(groups, volume)
        if stops > 2.0 * radius:
            closure = (float(end.efficiency[-1]) * volume / (2.0 * groups.C_prime * math.pi * stops**2)) ** 2
            basis = "arrest"
        else:
            closure = closure_after(float(end.efficiency[-1]), t_pump)
    steps = parcels = updates = None
    if scene.proppant is not None and scene.coupling is not None and first:
        numerics = scene.proppant.numerics
        side = min(scene.coupling.cell_size or (scene.mesh.dx, scene.mesh.dz))
        t0, w0 = min(first.values())
        courant = numerics.c_max * 4.0 * w0 * side**2 / rate
        steps = math.ceil((scene.run.end_time - t0) / min(numerics.dt_max, courant))
        parcels = numerics.max_parcels
        if parcels is not None:
            updates = float(steps) * numerics.particle_substeps * parcels
    return Estimate(pumping_time=t_pump, rate=rate, radius=radius, efficiency=float(end.efficiency[-1]),
                    opening=float(end.w0[-1]), first_openings=first, cells=cells, closure_after=closure,
                    closure_basis=basis,
                    proppant_steps=steps,
                    parcels=parcels, parcel_updates=updates)


def arrest_radius(groups: Any, volume: float) -> float:
    """Where a radial fracture holding ``volume`` [m^3] stops spreading after shut-in (module docstring): the
    smaller of the penny crack's R_K (inf without toughness) and the leak-off arrest radius R_a (``groups``:
    reference.radial.scaled_parameters, with leak-off)."""
    from .reference.penny import penny_arrest_radius
    from .reference.radial import leakoff_arrest_radius

    k_ic = groups.K_prime / math.sqrt(32.0 / math.pi)
    tough = penny_arrest_radius(groups.E_prime, k_ic, volume) if k_ic > 0.0 else math.inf
    return min(tough, leakoff_arrest_radius(groups.E_prime, groups.C_prime, volume, groups.mu_prime))


def closure_after(efficiency: float, pumping_time: float) -> float:
    """Time [s] after shut-in at which a fracture of this efficiency at the end of pumping closes (module
    docstring: Nolte's G at closure, G_c = (4 g_0 / pi) eta / (1 - eta))."""
    from scipy.optimize import brentq

    from .fracture.falloff import G_function, g0

    eta = min(max(efficiency, 1e-9), 1.0 - 1e-9)
    g_c = 4.0 * g0(CLOSURE_ALPHA) / math.pi * eta / (1.0 - eta)
    upper = 1.0
    while float(G_function(upper, CLOSURE_ALPHA)) < g_c:
        upper *= 4.0
    return pumping_time * brentq(lambda d: float(G_function(d, CLOSURE_ALPHA)) - g_c, 0.0, upper, xtol=1e-12)


def _clusters(scene: Any) -> int:
    """The clusters of the scene's ``[completion]`` (1 without)."""
    completion = getattr(scene, "completion", None)
    return 1 if completion is None else completion.clusters


def report(e: Estimate | None, scene: Any, system: str) -> str:
    """The lines ``hfgpu check`` prints under "expected" for ``e``, the scene's :func:`estimate` ("" for None)."""
    if e is None:
        return ""
    minutes = format_number(e.pumping_time / 60.0, 3)
    rate, radius = display_text(e.rate, "rate", system, DIGITS), display_text(e.radius, "length", system, DIGITS)
    n = _clusters(scene)
    share = f" (one of {n} clusters' equal shares)" if n > 1 else ""
    lines = [f"expected (a radial fracture at the mean rate {rate}{share} in the rock at the injection depth, Dontsov "
             "2016; layers ignored; docs/scene.md):",
             f"  {'at the end of pumping':32} {minutes} min: radius {radius}, "
             f"opening at the perforation {display_text(e.opening, 'width', system, DIGITS)}, fluid efficiency "
             f"{format_number(100.0 * e.efficiency, 2)} %",
             f"  {'fracture cells':32} ~{format_number(e.cells, 2)} (pi R^2 / cell area)"]
    if scene.run.end_time > e.pumping_time * (1.0 + 1e-9):
        closes = ("never (no leak-off)" if e.closure_after is None else
                  f"about {display_text(e.closure_after, 'time', system, DIGITS)} after shut-in ({_basis(e)})")
        lines.append(f"  {'closure':32} {closes}")
    for name, (t, w0) in e.first_openings.items():
        lines.append(f"  {'opening when ' + name + ' starts':32} {display_text(w0, 'width', system, DIGITS)} "
                     f"(t = {format_number(t / 60.0, 3)} min)")
    if e.proppant_steps is not None:
        work = f"~{format_number(e.proppant_steps, 2)} (dt_max or the fluid Courant step at the perforation)"
        if e.parcel_updates is not None:
            work += (f"; at most {format_number(e.parcels, 3)} parcels: ~{e.parcel_updates:.2g} parcel updates "
                     "(docs/benchmarks.md: the engines' speed)")
        lines.append(f"  {'proppant steps':32} {work}")
    return "\n".join(lines)


def _basis(e: Estimate) -> str:
    """What ``e.closure_after`` rests on, in words."""
    if e.closure_basis == "nolte":
        return "Nolte's G at that efficiency"
    return "Carter leak-off over the area where the fracture stops spreading after shut-in"


def warnings(e: Estimate | None, scene: Any, system: str) -> list[str]:
    """The module docstring's warnings for ``e``, the scene's :func:`estimate`, in the scene's units, naming the key
    each concerns."""
    if e is None:
        return []
    found = []
    cell = max(scene.mesh.dx, scene.mesh.dz)
    if e.radius < MIN_CELLS_RADIUS * cell:
        radius, side = display_text(e.radius, "length", system, DIGITS), display_text(cell, "length", system, DIGITS)
        found.append(f"injection.schedule: the fracture is expected to reach about {radius} from the perforation by "
                     f"the end of pumping (a radial estimate, Dontsov 2016), fewer than "
                     f"{MIN_CELLS_RADIUS} cells of {side}: the grid does not resolve it; "
                     "use finer cells ([mesh] cell_size) or a higher rate")
    if e.efficiency < MIN_EFFICIENCY:
        found.append(f"injection.schedule: only about {format_number(100.0 * e.efficiency, 2)} % of the pumped fluid "
                     f"is expected in the fracture at the end of pumping (rock.leakoff_coefficient at the injection "
                     f"depth, mean rate {display_text(e.rate, 'rate', system, DIGITS)}): leak-off takes nearly all of "
                     "it and the fracture stays small; a higher rate or a lower leak-off opens it")
    shut_in = scene.run.end_time - e.pumping_time
    if shut_in > LONG_SHUT_IN * e.pumping_time:
        closes = ("it never closes without leak-off" if e.closure_after is None else
                  f"the fracture is expected to close about {display_text(e.closure_after, 'time', system, DIGITS)} "
                  f"after shut-in ({_basis(e)})")
        found.append(f"run.end_time: the shut-in lasts {shut_in / e.pumping_time:.2g} times the pumping time; "
                     f"{closes}")
    if scene.proppant is None:
        return found
    factor = scene.proppant.params.bridging_factor
    for i, spec in enumerate(scene.proppant.classes):
        if spec.name not in e.first_openings:
            continue
        t, w0 = e.first_openings[spec.name]
        if factor * spec.size.d_max > w0:
            grain = display_text(spec.size.d_max, "width", system, DIGITS)
            opening = display_text(w0, "width", system, DIGITS)
            found.append(f"proppant[{i}] ({spec.name}): its largest grain {grain} "
                         f"x bridging_factor {factor:g} exceeds the expected opening at the perforation when it is "
                         f"first pumped, {opening} at {format_number(t / 60.0, 3)} min (a radial "
                         "estimate, Dontsov 2016): it bridges at the inlet unless the fracture is wider; a longer "
                         "pad, a higher rate or viscosity, or a finer grain")
    return found
