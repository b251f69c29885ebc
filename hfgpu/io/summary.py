"""What a run and ``hfgpu check`` print for a person: the run's summary as a short grouped table with units, and the
pump schedule as a treatment report shows it, both in the output units (``[output] units``, "SI" or "field";
docs/cli.md). The results file keeps every summary key in SI (``/summary``); these tables only choose and convert.

Summary groups and rows (a row whose value the run did not produce is left out; a time that never came, such as a
screen-out that did not happen, reads "never"):

* fracture (at the end of the run): created area (one face), length (tip to tip), height (the tallest column's
  open extent, hfgpu.fracture.geometry), width at the perforation, net pressure at the end;
* end of pumping (when the pumps stop before the end of the run, read from ``/fracture/balance``: the last record
  at or before :func:`pump_end`): length, height, net pressure, BHTP (and STP) there, and the ISIP (and at the
  surface);
* fall-off (a run with at least 2 records after the pumps stop, :func:`falloff_of`, hfgpu.fracture.falloff): the
  closure picked on G dP/dG (pressure, time after the stop, G_c) and Nolte's efficiency from G_c, or one line
  saying why none was picked;
* fluid: pumped, in the fracture, leaked off, fluid efficiency, bottom-hole treating pressure (BHTP) at the end,
  and with ``[wellbore]`` the surface treating pressure (STP, :mod:`hfgpu.wellbore`) at the end;
* clusters (a stage of several, ``[completion]``): each cluster's share of the fluid, created area, length, height;
* proppant: pumped, in the fracture (in the domain, for a proppant-only run), held back at the inlet (screen-out) and when it began, left the domain, parcels,
  and the closure results (propped area after closure, hfgpu.propped.headline_propped, and its share of the created
  area, propped half-length and height, mean
  conductivity, F_CD, at which time);
* run: status, simulated time, wall time, fracture and proppant steps, volume balance error, proppant engine,
  resumed from, results file.

Proppant amounts are masses where every class has the same grain density, else solid volumes. Numbers are
written by :func:`hfgpu.units.format_number` (4 significant figures, thousands grouped by a space: "13 020 lb").

Pressures (:func:`treatment_pressures`): BHTP is the fluid pressure in the perforated cell (``injection_pressure``
of ``/fracture/balance``, absolute like the layer stresses), STP its ``surface_pressure`` (:func:`surface_history`); ISIP is the BHTP of the first record after the pumps
stop (the first step of the shut-in: no extrapolation, the record itself).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..closure.display import in_units as closure_in_units
from ..closure.display import unit_label as closure_unit
from ..units import display_unit, format_number, in_display_units

#: The groups in the order they are printed.
GROUPS = ("fracture", "end of pumping", "fall-off", "fluid", "clusters", "proppant", "run")


def _first(summary: dict, *keys: str) -> Any:
    """The value of the first of ``keys`` the summary holds (fracture-only and coupled runs name some differently)."""
    for key in keys:
        if key in summary:
            return summary[key]
    return None


def _finite(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _quantity(value: Any, kind: str, system: str) -> str | None:
    if not _finite(value):
        return None
    return f"{format_number(in_display_units(float(value), kind, system))} {display_unit(kind, system)}"


def _percent(value: Any, digits: int = 3) -> str | None:
    return f"{format_number(100.0 * value, digits)} %" if _finite(value) else None


def _count(value: Any) -> str | None:
    return format_number(float(int(value)), max(len(str(abs(int(value)))), 1)) if _finite(value) else None


def _e_prime(scene: Any) -> float | None:
    """The scene's plane-strain modulus E' [Pa] (None without a rock)."""
    rock = getattr(scene, "rock", None)
    return None if rock is None else rock.plane_strain_modulus


def _when(value: Any, system: str = "SI") -> str:
    return _quantity(value, "time", system) if _finite(value) else "never"


def _proppant_amount(value: Any, density: float | None, system: str) -> str | None:
    if not _finite(value):
        return None
    if density is not None:
        return _quantity(value * density, "mass", system)
    return _quantity(value, "solid_volume", system)


def pump_end(scene: Any) -> float | None:
    """The time [s] the pumps stop: the end of the last stage pumping at a rate > 0; None without a schedule."""
    return scene.injection.schedule.pump_end if getattr(scene, "injection", None) is not None else None


def treatment_pressures(balance: dict[str, np.ndarray], stop: float | None,
                        stp: np.ndarray | None = None) -> dict[str, float]:
    """From a fracture step history (``/fracture/balance``) and the time the pumps stop: the state at the end of
    pumping, the last record at or before ``stop`` (``pumping_time`` [s], ``pumping_area`` [m^2],
    ``pumping_length``, ``pumping_height`` [m], ``pumping_net_pressure``, ``pumping_bhtp`` [Pa]), and ``isip``
    [Pa], the BHTP of the first record after ``stop``, at ``isip_time`` [s]. With ``stp``, the surface treating
    pressure of each record (:func:`hfgpu.wellbore.surface_pressure`), also ``pumping_stp`` and ``isip_surface``
    [Pa]. Empty when the history has no record after ``stop`` (the run ended pumping, or no stop)."""
    time = np.asarray(balance.get("time", ()), dtype=np.float64)
    if stop is None or not time.size or time[-1] <= stop or time[0] > stop:
        return {}
    last = int(np.searchsorted(time, stop, side="right")) - 1
    out = dict(pumping_time=time[last], pumping_area=balance["area"][last],
               pumping_length=balance["length"][last],
               pumping_height=balance["height"][last], pumping_net_pressure=balance["net_pressure"][last],
               pumping_bhtp=balance["injection_pressure"][last], isip=balance["injection_pressure"][last + 1],
               isip_time=time[last + 1])
    if stp is not None:
        out.update(pumping_stp=stp[last], isip_surface=stp[last + 1])
    return {k: float(v) for k, v in out.items()}


def falloff_of(balance: dict[str, np.ndarray] | None, stop: float | None, e_prime: float | None = None,
               alpha: float | None = None):
    """The fall-off of a step history (``/fracture/balance``) after the pumps stop at ``stop`` [s], read with G
    (:func:`hfgpu.fracture.falloff.falloff_analysis` on ``injection_pressure``, at ``alpha``, default the module's;
    the minimum stress at the injection depth is ``injection_pressure - net_pressure`` of the rows after the stop);
    with ``e_prime`` [Pa] also the apparent leak-off coefficient, read with the compliance of the footprint at the
    end of pumping (:func:`hfgpu.fracture.falloff.nolte_geometry`); None without at least 2 rows after ``stop``."""
    from ..fracture.falloff import DEFAULT_ALPHA, falloff_analysis, fracture_stiffness, nolte_geometry

    if not balance or stop is None or "injection_pressure" not in balance:
        return None
    time, bhp = np.asarray(balance["time"], dtype=np.float64), np.asarray(balance["injection_pressure"], np.float64)
    after = time > stop
    stress = bhp[after] - np.asarray(balance.get("net_pressure", np.full(time.shape, np.nan)), np.float64)[after]
    sigma_min = float(np.median(stress[np.isfinite(stress)])) if np.isfinite(stress).any() else math.nan
    stiffness, geometry = None, ""
    last = int(np.searchsorted(time, stop, side="right")) - 1
    if e_prime is not None and last >= 0 and all(k in balance for k in ("area", "length", "height")):
        shape, size = nolte_geometry(*(float(balance[k][last]) for k in ("area", "length", "height")))
        if size > 0.0:
            stiffness = fracture_stiffness(shape, e_prime, size)
            geometry = f"{shape}, {'h_f' if shape == 'pkn' else 'x_f' if shape == 'kgd' else 'R'} = {size:.4g} m"
    try:
        return falloff_analysis(time, bhp, stop, sigma_min, alpha=DEFAULT_ALPHA if alpha is None else alpha,
                                stiffness=stiffness, geometry=geometry)
    except ValueError:
        return None


#: The ``/summary`` attributes of a fall-off (:func:`falloff_values`), SI; NaN where the analysis has none.
FALLOFF_KEYS = ("isip", "sigma_min", "alpha", "closure_pressure", "closure_net_pressure", "closure_time", "G_c",
                "efficiency", "slope", "leakoff_coefficient")


def falloff_values(analysis: Any) -> dict[str, Any]:
    """A :func:`falloff_of` analysis as ``/summary`` attributes: ``falloff_<key>`` for :data:`FALLOFF_KEYS`
    (SI, NaN where it has none), ``falloff_geometry`` and ``falloff_note`` (strings, "" where it has none)."""
    values = {f"falloff_{k}": math.nan if getattr(analysis, k) is None else float(getattr(analysis, k))
              for k in FALLOFF_KEYS}
    return {**values, "falloff_geometry": analysis.geometry, "falloff_note": analysis.note}


def surface_history(balance: dict[str, np.ndarray] | None, scene: Any) -> np.ndarray | None:
    """The STP [Pa] of each record of ``/fracture/balance``: its ``surface_pressure`` column, stored for a scene
    with ``[wellbore]``; for a file written before hfgpu stored it (no column, or one shorter than ``time``),
    computed from ``scene``'s ``[wellbore]`` as the writer would (:func:`hfgpu.wellbore.surface_pressure`);
    None without either."""
    if not balance:
        return None
    stored = balance.get("surface_pressure")
    if stored is not None and stored.shape == balance["time"].shape:
        return stored
    if getattr(scene, "wellbore", None) is None:
        return None
    from ..wellbore import surface_pressure

    return surface_pressure(scene, balance["time"], balance["injection_pressure"])


def cluster_rows(summary: dict[str, Any], system: str) -> list[tuple[str, str, str]]:
    """The "clusters" group of a stage of several clusters (``cluster_<i>_*`` of the summary, hfgpu.fracture.stage):
    one row per cluster, its share of the fluid pumped, its created area, length and height at the end; with
    proppant (hfgpu.coupled_stage) its share of the proppant and its propped area after closure."""
    n = 0
    while f"cluster_{n}_area" in summary:
        n += 1
    if n < 2:
        return []
    total = sum(float(summary[f"cluster_{i}_injected"]) for i in range(n))
    rows = []
    for i in range(n):
        text = (f"{format_number(100.0 * summary[f'cluster_{i}_injected'] / total, 3)} % of the fluid, area "
                f"{_quantity(summary[f'cluster_{i}_area'], 'area', system)}, length "
                f"{_quantity(summary[f'cluster_{i}_length'], 'length', system)}, height "
                f"{_quantity(summary[f'cluster_{i}_height'], 'length', system)}")
        if f"cluster_{i}_solid_share" in summary:
            text += f"; {format_number(100.0 * summary[f'cluster_{i}_solid_share'], 3)} % of the proppant"
        if f"cluster_{i}_closure_propped_area" in summary:
            text += f", propped {_quantity(summary[f'cluster_{i}_closure_propped_area'], 'area', system)}"
        rows.append(("clusters", f"cluster {i + 1}", text))
    return rows


def _lead_cluster(summary: dict[str, Any]) -> int | None:
    """The cluster of a stage with the largest propped area after closure, whose half-length, height and F_CD the
    stage's closure values are (None for one fracture)."""
    areas = []
    while f"cluster_{len(areas)}_closure_propped_area" in summary:
        areas.append(float(summary[f"cluster_{len(areas)}_closure_propped_area"]))
    return int(np.argmax(areas)) if areas else None


def summary_rows(summary: dict[str, Any], system: str = "SI", density: float | None = None,
                 pressures: dict[str, float] | None = None,
                 stp_end: float | None = None, falloff: Any = None) -> list[tuple[str, str, str]]:
    """(group, label, value with its unit) of the rows the table shows, in order; ``density`` [kg/m^3] is the
    proppant's grain density when all classes share it (amounts then shown as masses); ``pressures`` is
    :func:`treatment_pressures` of the run (no end-of-pumping group without it); ``stp_end`` the STP [Pa] of the
    last record (no STP row without it); ``falloff`` the run's :func:`falloff_of` (no fall-off group without
    it)."""
    s = summary
    rows: list[tuple[str, str, str | None]] = []

    def add(group: str, label: str, text: str | None) -> None:
        rows.append((group, label, text))

    area = _first(s, "area", "fracture_area")
    add("fracture", "created area (one face)", _quantity(area, "area", system))
    add("fracture", "length (tip to tip)", _quantity(_first(s, "length", "fracture_length"), "length", system))
    add("fracture", "height", _quantity(_first(s, "height", "fracture_height"), "length", system))
    add("fracture", "width at the perforation", _quantity(_first(s, "w_inlet", "fracture_w_inlet"), "width", system))
    add("fracture", "net pressure at the end", _quantity(s.get("net_pressure_end"), "pressure", system))
    closed = _first(s, "closed_at", "fracture_closed_at")
    add("fracture", "closed (every cell)", _when(closed, system) if _finite(closed) else None)
    p = pressures or {}
    if p:
        add("end of pumping", "at", _when(p["pumping_time"], system))
        add("end of pumping", "created area (one face)", _quantity(p.get("pumping_area"), "area", system))
        add("end of pumping", "length (tip to tip)", _quantity(p["pumping_length"], "length", system))
        add("end of pumping", "height", _quantity(p["pumping_height"], "length", system))
        add("end of pumping", "net pressure", _quantity(p["pumping_net_pressure"], "pressure", system))
        add("end of pumping", "BHTP", _quantity(p["pumping_bhtp"], "pressure", system))
        add("end of pumping", "STP", _quantity(p.get("pumping_stp"), "pressure", system))
        isip = _quantity(p["isip"], "pressure", system)
        add("end of pumping", "ISIP", f"{isip} (first record after, {_when(p['isip_time'], system)})" if isip else None)
        add("end of pumping", "ISIP at surface", _quantity(p.get("isip_surface"), "pressure", system))
    if falloff is not None:
        rows += falloff_rows(falloff, system)

    add("fluid", "pumped", _quantity(s.get("injected_volume"), "volume", system))
    add("fluid", "in the fracture", _quantity(s.get("stored_volume"), "volume", system))
    add("fluid", "leaked off", _quantity(s.get("leaked_volume"), "volume", system))
    add("fluid", "fluid efficiency", _percent(s.get("efficiency")))
    add("fluid", "BHTP (bottom-hole treating pressure), end", _quantity(s.get("injection_pressure_end"), "pressure",
                                                                         system))
    add("fluid", "STP (surface treating pressure), end", _quantity(stp_end, "pressure", system))

    rows += cluster_rows(s, system)

    pumped = s.get("proppant_injected")
    add("proppant", "pumped", _proppant_amount(pumped, density, system))
    where = "in the fracture" if area is not None else "in the domain"   # a proppant-only run has a box or slot
    add("proppant", where, _proppant_amount(s.get("proppant_in_domain"), density, system))
    screened = _first(s, "proppant_screened_out", "screened_out")
    if _finite(pumped) and _finite(screened):
        held = _proppant_amount(screened, density, system)
        if pumped > 0 and screened > 0:
            held += f" ({format_number(100.0 * screened / pumped, 3)} % of pumped)"
        add("proppant", "held back at the inlet", held)
        add("proppant", "screen-out began", _when(_first(s, "proppant_screen_out_time", "screen_out_time"), system))
    if "tip_screen_out_time" in s:   # a two-way coupled run (hfgpu.coupled.simulate_two_way)
        tso = s["tip_screen_out_time"]
        add("proppant", "tip screen-out", _when(tso, system))
        if _finite(tso):
            add("proppant", "net pressure rise after it", _quantity(s.get("net_pressure_rise"), "pressure", system))
        add("proppant", "packed length", _quantity(s.get("packed_length"), "length", system))
    outflow = s.get("proppant_outflow")
    if _finite(outflow) and outflow > 0:
        add("proppant", "left the domain", _proppant_amount(outflow, density, system))
    add("proppant", "parcels", _count(_first(s, "proppant_parcels", "parcels")))
    if "closure_propped_area" in s:
        propped = s["closure_propped_area"]
        text = f"{format_number(closure_in_units('propped_area', propped, system))} {closure_unit('propped_area', system)}"
        if _finite(area) and area > 0:
            text += f" ({format_number(100.0 * propped / area, 3)} % of created)"
        add("proppant", "propped area (after closure)", text)
        lead = _lead_cluster(s)
        for name, label in (("propped_half_length", "propped half-length"), ("propped_height", "propped height"),
                            ("mean_conductivity", "mean conductivity"), ("fcd", "F_CD")):
            value = s.get(f"closure_{name}")
            if _finite(value):
                unit = closure_unit(name, system)
                if lead is not None and name != "mean_conductivity":   # hfgpu.closure.conductivity.close
                    label += f" (cluster {lead + 1})"
                add("proppant", label, f"{format_number(closure_in_units(name, value, system))} {unit}".rstrip())
        if s.get("closure_permeability_model") == "kozeny-carman":
            add("proppant", "permeability", "Kozeny-Carman, independent of closure stress (no conductivity table)")
        add("proppant", "closure at", _when(s.get("closure_time"), system))

    add("run", "status", str(s["status"]) if "status" in s else None)
    add("run", "simulated time", _quantity(s.get("sim_time"), "time", system))
    add("run", "wall time", f"{format_number(s['wall_time'], 3)} s" if _finite(s.get("wall_time")) else None)
    add("run", "fracture steps", _count(s.get("fracture_steps")))
    add("run", "proppant steps", _count(s.get("proppant_steps")))
    balance = s.get("balance_error")
    add("run", "volume balance error", "< 0.01 %" if _finite(balance) and abs(balance) < 1e-4 else _percent(balance, 2))
    backend = _first(s, "proppant_backend", "backend")
    if backend is not None and "proppant_injected" in s:
        arch = _first(s, "proppant_arch", "arch")
        add("run", "proppant engine", f"{backend}" + (f" ({arch})" if arch else ""))
    if _finite(s.get("resumed_from")):
        add("run", "resumed from", _when(s["resumed_from"], system))
    add("run", "results file", str(s["out"]) if "out" in s else None)
    return [(g, label, text) for g, label, text in rows if text is not None]


def falloff_rows(falloff: Any, system: str = "SI", isip: bool = False) -> list[tuple[str, str, str | None]]:
    """The "fall-off" group's (group, label, text) rows of a :func:`falloff_of` analysis in ``system``'s units:
    the closure picked (pressure, time after the stop, G_c, Nolte's efficiency) or why none was, and the apparent
    leak-off coefficient when it has one; with ``isip`` first the ISIP and the minimum stress it is read against."""
    rows: list[tuple[str, str, str | None]] = []

    def add(label: str, text: str | None) -> None:
        rows.append(("fall-off", label, text))

    if isip:
        add("ISIP (first record after the stop)", _quantity(falloff.isip, "pressure", system))
        add("minimum stress at the injection depth", _quantity(falloff.sigma_min, "pressure", system))
    if falloff.closure is None:
        add("closure", f"not picked: {falloff.note}")
    else:
        add("closure pressure", _quantity(falloff.closure_pressure, "pressure", system))
        add("closure time after shut-in", _when(falloff.closure_time, system))
        add(f"G at closure (alpha = {falloff.alpha:g})", format_number(falloff.G_c, 4))
        add("efficiency at shut-in (Nolte, from G)", _percent(falloff.efficiency))
    if falloff.leakoff_coefficient is not None:
        add(f"apparent leak-off coefficient ({falloff.geometry})",
            _quantity(falloff.leakoff_coefficient, "leakoff", system))
    return rows


def falloff_report(path: Any, alpha: float | None = None) -> str:
    """``hfgpu falloff``: the fall-off of the results file ``path`` (:func:`falloff_of`, G at ``alpha``) as a
    table in its scene's units, with the ISIP. Raises HfgpuError, one line, for a run with no shut-in to read."""
    from ..errors import HfgpuError
    from .results import open_results

    results = open_results(path)
    scene, balance = results.scene, results.fracture_balance
    stop = pump_end(scene)
    if not balance or stop is None:
        raise HfgpuError(f"{path}: no fall-off to analyse: the run has no fracture pressure history")
    analysis = falloff_of(balance, stop, _e_prime(scene), alpha)
    if analysis is None:   # fewer than 2 records after the stop
        raise HfgpuError(f"{path}: no fall-off to analyse: the run has no shut-in (pumping until {stop:g} s, "
                         f"records until {balance['time'][-1]:g} s); a shut-in is a last stage at rate 0")
    return _table([row for row in falloff_rows(analysis, scene.output.units, isip=True) if row[2] is not None])


def _table(rows: list[tuple[str, str, str | None]]) -> str:
    width = max((len(label) for _, label, _ in rows), default=0)
    lines, group = [], None
    for g, label, text in rows:
        if g != group:
            lines.append(g)
            group = g
        lines.append(f"  {label:<{width}}  {text}")
    return "\n".join(lines)


def shared_density(scene: Any) -> float | None:
    """The grain density [kg/m^3] all proppant classes of ``scene`` share, None if they differ (or no proppant)."""
    if scene is None or getattr(scene, "proppant", None) is None:
        return None
    densities = set(scene.proppant.class_densities().values())
    return densities.pop() if len(densities) == 1 else None


def summary_table(summary: dict[str, Any], system: str = "SI", scene: Any = None,
                  balance: dict[str, np.ndarray] | None = None, falloff: Any = None) -> str:
    """The run's summary as a grouped text table (:data:`GROUPS`) in ``system``'s units; ``balance`` is the run's
    ``/fracture/balance`` (default: read from the summary's results file ``out`` when there is one), ``falloff``
    its :func:`falloff_of` analysis (default: computed from ``balance``)."""
    if balance is None and "out" in summary:
        from ..errors import HfgpuError
        from .results import open_results

        try:
            balance = open_results(summary["out"]).fracture_balance
        except (HfgpuError, OSError):
            balance = None
    stp = surface_history(balance, scene)
    pressures = treatment_pressures(balance, pump_end(scene), stp) if balance and scene is not None else None
    stp_end = float(stp[-1]) if stp is not None and stp.size else None
    if falloff is None and balance and scene is not None:
        falloff = falloff_of(balance, pump_end(scene), _e_prime(scene))
    return _table(summary_rows(summary, system, shared_density(scene), pressures, stp_end, falloff))


# ----------------------------------------------------------------------------------------------
# the pump schedule


def schedule_rows(scene: Any) -> list[dict[str, Any]]:
    """One dict per stage of the scene's schedule, in SI: stage (1-based), kind ("pad", "slurry" or "shut-in"),
    proppant, start, end [s], rate (slurry) [m^3/s], slurry and clean volume [m^3], solids volume [m^3], proppant
    mass [kg] (None without a grain density), concentration at start and end [kg per m^3 of clean fluid]. Kinds:
    "pad" (clean fluid before proppant), "slurry", "flush" (clean fluid after proppant), "fluid" (a schedule without
    proppant), "shut-in" (rate 0).

    Within a stage the slurry rate Q is constant and the slurry volume fraction phi linear in time, so the solids
    volume is Q dt (phi_0 + phi_1) / 2 exactly, the clean volume Q dt less that, and the concentration
    rho_p phi / (1 - phi)."""
    densities = scene.proppant.class_densities() if getattr(scene, "proppant", None) is not None else {}
    rows, start = [], 0.0
    stages = scene.injection.schedule.stages
    for i, stage in enumerate(stages):
        slurry = stage.rate * (stage.until - start)
        solids = slurry * 0.5 * (stage.volume_fraction + stage.end_volume_fraction)
        density = densities.get(stage.proppant)
        if stage.rate <= 0.0:
            kind = "shut-in"
        elif stage.proppant is not None:
            kind = "slurry"
        else:  # clean fluid: a pad before the proppant, a flush after it, plain fluid in a schedule without any
            kind = "flush" if any(s.proppant for s in stages[:i]) else \
                ("pad" if any(s.proppant for s in stages[i:]) else "fluid")
        concentration = [density * phi / (1.0 - phi) if density is not None else None
                         for phi in (stage.volume_fraction, stage.end_volume_fraction)]
        rows.append(dict(stage=i + 1, kind=kind, proppant=stage.proppant, start=start, end=stage.until,
                         rate=stage.rate, slurry_volume=slurry, clean_volume=slurry - solids, solid_volume=solids,
                         mass=solids * density if density is not None else None,
                         concentration_start=concentration[0], concentration_end=concentration[1]))
        start = stage.until
    return rows


def schedule_table(scene: Any, system: str = "SI") -> str:
    """The pump schedule as a text table in ``system``'s units (times in minutes in field units), with a total
    row."""
    rows = schedule_rows(scene)
    u = {kind: display_unit(kind, system) for kind in ("rate", "volume", "mass", "concentration")}
    u["time"] = "min" if system == "field" else display_unit("time", system)
    header = ["stage", "", f"start [{u['time']}]", f"end [{u['time']}]", f"rate [{u['rate']}]",
              f"clean [{u['volume']}]", f"slurry [{u['volume']}]", f"proppant [{u['mass']}]",
              f"conc. [{u['concentration']}]"]

    def number(value: Any, kind: str) -> str:
        if kind == "time" and system == "field":
            return format_number(value / 60.0)
        return "-" if value is None else format_number(in_display_units(value, kind, system))

    body = []
    for r in rows:
        c0, c1 = r["concentration_start"], r["concentration_end"]
        if r["kind"] != "slurry":
            conc = "-"
        elif c0 is None:
            conc = "?"
        elif math.isclose(c0, c1, rel_tol=1e-9):
            conc = number(c0, "concentration")
        else:
            conc = f"{number(c0, 'concentration')}-{number(c1, 'concentration')}"
        label = r["kind"] + (f" {r['proppant']}" if r["proppant"] else "")
        body.append([str(r["stage"]), label, number(r["start"], "time"), number(r["end"], "time"),
                     number(r["rate"], "rate"), number(r["clean_volume"], "volume"),
                     number(r["slurry_volume"], "volume"),
                     "-" if r["kind"] != "slurry" else number(r["mass"], "mass"), conc])
    masses = [r["mass"] for r in rows if r["kind"] == "slurry"]
    total_mass = None if any(m is None for m in masses) else sum(masses)
    body.append(["total", "", "", number(rows[-1]["end"], "time") if rows else "", "",
                 number(sum(r["clean_volume"] for r in rows), "volume"),
                 number(sum(r["slurry_volume"] for r in rows), "volume"),
                 number(total_mass, "mass") if masses else "-", ""])
    if not any(r["kind"] == "slurry" for r in rows):  # no proppant: no proppant columns
        header, body = header[:-2], [line[:-2] for line in body]
    widths = [max(len(line[k]) for line in [header, *body]) for k in range(len(header))]
    lines = ["pump schedule"]
    for line in [header, *body]:
        cells = [text.ljust(w) if k < 2 else text.rjust(w) for k, (text, w) in enumerate(zip(line, widths))]
        lines.append("  " + "  ".join(cells).rstrip())
    return "\n".join(lines)
