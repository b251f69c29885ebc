"""Report of the speed-accuracy study (bench/study.py): docs/speed-accuracy.md, figures/pareto.png and
figures/convergence.png from the study's runs."""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib
import matplotlib.ticker

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from _study_cases import CASES, FIELD_CASES, PRESET_KNOBS, PRESETS, SCENES, Run, load_scene  # noqa: E402
from _study_plan import QUICK_SKIP  # noqa: E402

GROUP_STYLE = {"preset": ("k", "*"), "space": ("tab:blue", "o"), "time": ("tab:orange", "s"),
               "newton": ("tab:green", "^"), "parcels": ("tab:purple", "D"), "dt": ("tab:brown", "v"),
               "substeps": ("tab:pink", "P"), "seeds": ("tab:gray", "."), "reference": ("tab:red", "X")}
#: Error bounds of the recommendation rule: screening within 10 %, design within 5 % on every case.
SCREENING_BOUND, DESIGN_BOUND = 0.10, 0.05


def _by_case(runs: list[Run]) -> dict[str, list[Run]]:
    out: dict[str, list[Run]] = {}
    for r in runs:
        out.setdefault(r.case, []).append(r)
    return out


def _cell(case: str) -> float:
    """The case scene's cell size along z [m] at refinement 1."""
    return float(load_scene(SCENES / CASES[case].scene).mesh.dz)


def _fmt(x: float, pct: bool = True) -> str:
    if not np.isfinite(x):
        return "-"
    return f"{100 * x:.2f} %" if pct else f"{x:.3g}"


# ------------------------------------------------------------------------------------------------------------
# analysis shared by the figures and the text


def pareto_front(points) -> list[int]:
    """Indices of the non-dominated points of (cost, error) pairs, cheapest first: a point is dominated when
    another is no costlier and no less accurate and better in one of the two. NaN points are left out."""
    pts = [(i, float(c), float(e)) for i, (c, e) in enumerate(points) if np.isfinite(c) and np.isfinite(e)]
    front = [i for i, c, e in pts
             if not any(c2 <= c and e2 <= e and (c2 < c or e2 < e) for _, c2, e2 in pts)]
    return sorted(front, key=lambda i: (points[i][0], points[i][1]))


def fitted_order(h, err) -> float:
    """Slope of log|err| against log h (least squares): the observed convergence order; NaN with < 2 points."""
    h, err = np.asarray(h, dtype=np.float64), np.abs(np.asarray(err, dtype=np.float64))
    use = np.isfinite(h) & np.isfinite(err) & (err > 0.0) & (h > 0.0)
    if use.sum() < 2:
        return math.nan
    return float(np.polyfit(np.log(h[use]), np.log(err[use]), 1)[0])


def convergence(runs: list[Run], case: str, group: str) -> dict:
    """Series of one sweep (space: h = cell size [m]; time: lambda) of a case: the step h, the signed errors of
    each part against the reference, the quantities themselves, the observed orders (slope of log|err| against
    log h, and of log|q - q_finest| for self-convergence) and whether the |error| series is monotone."""
    sel = [r for r in runs if r.case == case and r.group == group and r.values]
    if group == "space":
        h = np.array([_cell(case) / r.knobs.refinement for r in sel])
    else:
        h = np.array([r.knobs.time_step_relaxation for r in sel])
    order = np.argsort(h)[::-1]
    sel, h = [sel[i] for i in order], h[order]
    out = dict(h=h, runs=sel, failed=[r for r in runs if r.case == case and r.group == group
                                      and not r.values], parts={}, order={}, self_order={}, monotone={})
    if not sel:
        return out
    for part in sel[0].parts:
        err = np.array([r.parts[part] for r in sel])
        q = np.array([r.values[part] for r in sel])
        out["parts"][part] = err
        out["order"][part] = fitted_order(h, err)
        out["self_order"][part] = fitted_order(h[:-1], (q[:-1] - q[-1]) / q[-1]) if len(sel) > 2 else math.nan
        out["monotone"][part] = bool(np.all(np.diff(np.abs(err)) <= 0.0) and np.all(np.sign(err) == np.sign(err[0])))
    return out


def parcel_study(runs: list[Run], case: str) -> list[dict]:
    """A field case: per parcels_per_cell, the propped area's mean, standard deviation, min and max over seeds,
    the mean fracture area and CPU seconds."""
    sel = [r for r in runs if r.case == case and r.group == "seeds" and r.values]
    rows = []
    for n in sorted({r.knobs.parcels_per_cell for r in sel}):
        group = [r for r in sel if r.knobs.parcels_per_cell == n]
        area = np.array([r.values["propped_area"] for r in group])
        frac = np.array([r.values["propped_fraction"] for r in group])
        rows.append(dict(ppc=n, seeds=len(group), mean=float(area.mean()), std=float(area.std(ddof=1)) if len(group) > 1
                         else math.nan, min=float(area.min()), max=float(area.max()), fraction=float(frac.mean()),
                         parcels=float(np.mean([r.parcels for r in group])),
                         cpu=float(np.mean([r.cpu for r in group])), areas=area))
    return rows


def preset_summary(runs: list[Run]) -> dict[str, dict[str, Run]]:
    """{preset: {case: run}}."""
    out: dict[str, dict[str, Run]] = {p: {} for p in PRESETS}
    for r in runs:
        if r.group == "preset":
            out[r.label][r.case] = r
    return out


def recommend(summary: dict[str, dict[str, Run]]) -> list[tuple[str, str, str]]:
    """(use, preset, reason with numbers): screening = the cheapest preset that runs every case and stays within
    SCREENING_BOUND on every case with an outside reference, design = the cheapest within DESIGN_BOUND,
    validation = the preset with the lowest error on the most cases (ties: lower mean log error)."""
    cases = sorted({c for runs in summary.values() for c in runs})
    if not cases:
        return []
    outside = [c for c in cases if CASES[c].errors.__name__ != "_relative_to"]

    def worst(p):
        if any(c in summary[p] and not summary[p][c].values for c in cases):
            return math.inf
        errs = [summary[p][c].error if c in summary[p] else math.nan for c in outside]
        return math.inf if not errs or any(not np.isfinite(e) for e in errs) else max(errs)

    def cpu(p):
        return sum(summary[p][c].cpu for c in cases if c in summary[p] and np.isfinite(summary[p][c].cpu))

    def describe(p):
        parts = {True: [], False: []}  # against an outside reference, against the most accurate run
        for c in cases:
            r = summary[p].get(c)
            if r is None or not np.isfinite(r.error):
                text = f"{c} {'failed' if r is not None and not r.values else '-'}"
            elif r.note.startswith("reference"):
                text = f"{c} reference"
            else:
                text = f"{c} {100 * r.error:.1f} %"
            parts[c in outside].append(text)
        own = f"; against its most accurate run {', '.join(parts[False])}" if parts[False] else ""
        return f"errors {', '.join(parts[True])}{own}; {cpu(p):.1f} CPU s over the cases"

    out = []
    names = list(PRESETS)  # fastest first
    for use, bound in (("screening", SCREENING_BOUND), ("design", DESIGN_BOUND)):
        ok = [p for p in names if worst(p) <= bound]
        if ok:
            p = ok[0]
            cheaper = [q for q in names[:names.index(p)]]
            why = f"cheapest preset within {100 * bound:.0f} % on every case with an outside reference: {describe(p)}"
            if cheaper:
                why += "; " + "; ".join(f"{q} is out ({describe(q)})" for q in cheaper)
        else:
            p = min(names, key=worst)
            why = (f"no preset is within {100 * bound:.0f} % on every case with an outside reference; {p} has the "
                   f"smallest worst error: {describe(p)}")
        out.append((use, p, why))

    def wins(p):
        return sum(1 for c in outside if all(
            summary[p].get(c) is not None and np.isfinite(summary[p][c].error)
            and (summary[q].get(c) is None or not np.isfinite(summary[q][c].error)
                 or summary[p][c].error <= summary[q][c].error) for q in names))

    def mean_log(p):
        errs = [summary[p][c].error for c in outside if c in summary[p] and np.isfinite(summary[p][c].error)]
        return np.mean(np.log(np.maximum(errs, 1e-12))) if errs else math.inf

    best = max(names, key=lambda p: (wins(p), -mean_log(p)))
    out.append(("validation", best, f"lowest error on {wins(best)} of the {len(outside)} cases with an outside "
                                    f"reference: {describe(best)}"))
    return out


# ------------------------------------------------------------------------------------------------------------
# figures


def pareto_figure(runs: list[Run], path: Path) -> None:
    """Error against CPU seconds, log-log, one panel per case; Pareto front as a line, presets labelled."""
    by_case = _by_case(runs)
    n = len(by_case)
    cols = min(n, 3)
    rows_ = -(-n // cols)
    fig, axes = plt.subplots(rows_, cols, figsize=(4.6 * cols, 3.9 * rows_), squeeze=False)
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    for ax, (case, rows) in zip(axes.flat, by_case.items()):
        ok = [r for r in rows if np.isfinite(r.error) and r.error > 0 and np.isfinite(r.cpu)]
        for group in GROUP_STYLE:
            sel = [r for r in ok if r.group == group and group != "preset"]
            if sel:
                colour, marker = GROUP_STYLE[group]
                ax.loglog([r.cpu for r in sel], [r.error for r in sel], marker, color=colour, ms=5, alpha=0.75,
                          ls="none", label=group)
        front = [ok[i] for i in pareto_front([(r.cpu, r.error) for r in ok])]
        if front:
            ax.loglog([r.cpu for r in front], [r.error for r in front], "-", color="tab:red", lw=1,
                      label="Pareto front")
        for r in ok:
            if r.group == "preset":
                ax.loglog(r.cpu, r.error, "*", color="k", ms=13)
                ax.annotate(r.label, (r.cpu, r.error), textcoords="offset points", xytext=(6, 4), fontsize=8)
        failed = sum(1 for r in rows if not r.values)
        ax.set_title(f"{case}" + (f" ({failed} failed)" if failed else ""), fontsize=10)
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.yaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_xlabel("CPU s (one thread)")
        ax.set_ylabel("error vs most accurate run" if CASES[case].errors.__name__ == "_relative_to" else "error")
        ax.grid(True, which="both", alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def convergence_figure(runs: list[Run], path: Path) -> None:
    """Space and time convergence of the fracture engine (radial I, III) and propped area against parcels per
    cell over seeds (field)."""
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.2))
    for case, colour in (("radial_I", "tab:blue"), ("radial_III", "tab:orange")):
        s = convergence(runs, case, "space")
        for part, style in (("R", "o-"), ("w0", "s--")):
            if part in s["parts"]:
                axes[0].loglog(s["h"], np.abs(s["parts"][part]), style, color=colour,
                               label=f"{case} {part} (order {s['order'][part]:.2f})")
        t = convergence(runs, case, "time")
        for part, style in (("R", "o-"), ("w0", "s--")):
            if part in t["parts"] and len(t["runs"]) > 2:
                q = np.array([r.values[part] for r in t["runs"]])
                axes[1].loglog(t["h"][:-1], np.abs(q[:-1] / q[-1] - 1), style, color=colour,
                               label=f"{case} {part} (order {t['self_order'][part]:.2f})")
    axes[0].set_xlabel("cell size [m] (relaxation 0.25)")
    axes[0].set_ylabel("|error| vs Dontsov (2016)")
    axes[0].set_title("space")
    axes[1].set_xlabel("time-step relaxation lambda (Eq. 35)")
    axes[1].set_ylabel("|q(lambda) / q(lambda_min) - 1|")
    axes[1].set_title("time (against the smallest lambda)")
    for case, colour in zip(FIELD_CASES, ("tab:purple", "tab:green")):
        rows = parcel_study(runs, case)
        if not rows:
            continue
        ax = axes[2]
        n = np.array([r["ppc"] for r in rows])
        for r in rows:
            ax.plot(np.full(r["areas"].size, r["ppc"]), r["areas"], ".", color="tab:gray")
        ax.errorbar(n, [r["mean"] for r in rows], yerr=[np.nan_to_num(r["std"]) for r in rows], fmt="o-",
                    color=colour, capsize=3, label=f"{case}: mean +- std over seeds")
        ax.set_xscale("log", base=2)
        ax.set_xlabel("parcels per cell")
        ax.set_ylabel("propped area [m$^2$]")
        ax.set_title("field (scaled demo): propped area")
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


# ------------------------------------------------------------------------------------------------------------
# text


def _case_table(rows: list[Run]) -> list[str]:
    ok = [r for r in rows if np.isfinite(r.error) and np.isfinite(r.cpu)]
    front = {id(ok[i]) for i in pareto_front([(r.cpu, r.error) for r in ok])}
    parts = list(next((r.parts for r in rows if r.parts), {}))
    show_parts = len(parts) <= 4
    head = "| group | setting | cells | parcels | steps | CPU s | wall s | error |"
    head += "".join(f" {p} |" for p in parts) if show_parts else ""
    head += " Pareto | note |"
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for r in rows:
        line = (f"| {r.group} | {r.label} | {r.cells} | {r.parcels} | {r.steps} | {_fmt(r.cpu, False)} | "
                f"{_fmt(r.wall, False)} | {_fmt(r.error)} |")
        if show_parts:
            line += "".join(f" {_fmt(r.parts.get(p, math.nan))} |" for p in parts)
        line += f" {'yes' if id(r) in front else ''} | {r.note} |"
        lines.append(line)
    return lines


def _commit() -> str:
    """The short hash of the checkout's HEAD ("unknown" outside a git checkout)."""
    import subprocess

    try:
        done = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, timeout=10,
                              cwd=Path(__file__).resolve().parent)
    except OSError:
        return "unknown"
    return done.stdout.strip() if done.returncode == 0 else "unknown"


def write_report(runs: list[Run], meta: dict, out: Path) -> list[Path]:
    """Write speed-accuracy.md and the two figures under ``out``; returns their paths."""
    out = Path(out)
    (out / "figures").mkdir(parents=True, exist_ok=True)
    pareto, conv, doc = out / "figures" / "pareto.png", out / "figures" / "convergence.png", out / "speed-accuracy.md"
    pareto_figure(runs, pareto)
    convergence_figure(runs, conv)
    by_case = _by_case(runs)
    summary = preset_summary(runs)
    L: list[str] = []
    L += ["# Speed and accuracy: the measured trade", "",
          f"Generated by `python bench/study.py{' --quick' if meta['quick'] else ''}` on {meta['started']} at "
          f"commit {_commit()} "
          f"({'quick' if meta['quick'] else 'full'} sweep, particle kernels: {meta['backend']}); "
          f"{meta['cpu_total']:.0f} CPU s, {meta['wall_total']:.0f} wall s in all. Machine: {meta['cores']} cores "
          f"shared with other jobs (load average {meta['load'][0][0]:.1f} at the start, {meta['load'][1][0]:.1f} "
          "at the end), so **CPU seconds** (time.process_time of the run, OMP/BLAS/Taichi threads at 1) are the "
          "measure of cost; wall seconds, printed beside them, mostly measure the other jobs. Errors are "
          "deterministic (fixed scenes and seeds): a re-run reproduces them; CPU times move by some 10-20 %.", "",
          "![error against CPU time](figures/pareto.png)", "",
          "![convergence](figures/convergence.png)", "",
          "## Method", "",
          "Each case runs at the three presets and along one-knob sweeps around its scene (the other knobs at "
          "the scene's values). Error measures (none tuned; the references are not ours):", ""]
    for name in by_case:
        L.append(f"* **{name}** (`hfgpu/scenes/{CASES[name].scene}`): {CASES[name].reference}.")
    L += ["", "The field cases: `field` and `field_100mesh` are the scaled five-layer demo (90 s: 30 s pad, 60 s "
          "of slurry; 40/70 screens out at its perforation, 100 mesh does not), swept over parcel counts and "
          "seeds; `field_base` is the paper's 3600 s base case (hfgpu/scenes/five_layer.toml) at the fast and "
          "balanced presets (the accurate preset's 2.5 m cells would take about an hour of CPU). Their errors are "
          "relative to the most accurate run affordable (group `reference`: the accurate preset with 64 parcels "
          "per cell for the demo, refinement 1.5 with relaxation 0.25 for the base case; the quick study's "
          "accurate preset run), not to an outside reference, so they measure convergence, not correctness. "
          "Propped area counts whole cells (25 m^2 each on a 5 m mesh), so one cell more or less moves it by "
          "several per cent on the demo.", "",
          "Columns: `cells` = active fracture elements at the end (fracture cases), grid cells (Davis), fracture "
          "elements + proppant grid cells (field); `parcels` = parcels at the end; `steps` = fracture steps + "
          "fluid steps; `error` as above (a failed run has none: its note says why).", "",
          "Presets (the values this study used are in the table below): those of `hfgpu/presets.py` when the "
          "study ran, applied through the knobs "
          "(`bench/_study_cases.py`). "
          "As in hfgpu, a key the case's scene file sets itself wins over the preset: davis1982.toml sets "
          "`parcels_per_cell = 16` and `dt_max = 2 s`, five_layer_demo.toml `parcels_per_cell = 8`; the sweeps "
          "vary those keys separately. Mesh refinement divides the cell size (for the Davis column dz only: "
          "the column stays one cell wide, see its scene).", "",
          "| knob | " + " | ".join(PRESETS) + " |", "|---|" + "---|" * len(PRESETS)]
    if meta["quick"]:
        L[-2:-2] = ["The quick study (`--quick`) runs fewer settings and leaves out " +
                    ", ".join(f"the {p} preset on {c}" for c, p in sorted(QUICK_SKIP)) + " for its cost.", ""]
    for field in PRESET_KNOBS:
        L.append(f"| {field} | " + " | ".join(f"{getattr(k, field):g}" for k in meta["presets"].values()) + " |")
    L += ["", "## Presets per case", "", "| case | " + " | ".join(f"{p} error | {p} CPU s" for p in PRESETS) + " |",
          "|---|" + "---|---|" * len(PRESETS)]
    for case in by_case:
        cells = []
        for p in PRESETS:
            r = summary[p].get(case)
            error = "failed" if r is not None and not r.values else (
                "reference" if r is not None and r.note.startswith("reference") else _fmt(getattr(r, "error", math.nan)))
            cells.append("- | -" if r is None else f"{error} | {_fmt(r.cpu, False)}")
        L.append(f"| {case} | " + " | ".join(cells) + " |")
    L += ["", "## Recommended preset per use", "",
          f"Rule (computed from the table above, so it follows a re-run): screening = the cheapest preset that "
          f"runs every case and is within {100 * SCREENING_BOUND:.0f} % on every case with an outside reference "
          f"(all but the field case), design = the cheapest within {100 * DESIGN_BOUND:.0f} %, validation = the "
          "preset with the lowest error on the most cases.", ""]
    for use, preset, why in recommend(summary) or [("none", "-", "no preset runs in this study")]:
        L.append(f"* **{use}: `{preset}`** -- {why}.")
    L += ["", "## What each knob moves", "",
          "Per case and sweep: the range of the error and of the CPU time over the sweep's settings (the other "
          "knobs at the scene's values). A knob whose error range is narrow buys little on that case.", "",
          "| case | sweep | settings | error min .. max | CPU s min .. max | failed |", "|---|---|---|---|---|---|"]
    for case, case_rows in by_case.items():
        for group in dict.fromkeys(r.group for r in case_rows):
            sel = [r for r in case_rows if r.group == group]
            ok = [r for r in sel if np.isfinite(r.error)]
            err = f"{_fmt(min(r.error for r in ok))} .. {_fmt(max(r.error for r in ok))}" if ok else "-"
            cpu = (f"{min(r.cpu for r in ok):.3g} .. {max(r.cpu for r in ok):.3g}" if ok else "-")
            L.append(f"| {case} | {group} | {', '.join(r.label for r in sel)} | {err} | {cpu} | "
                     f"{sum(1 for r in sel if not r.values)} |")
    conv_rows: list[str] = []
    for case in ("radial_I", "radial_III", "wu2008"):
        for group in ("space", "time"):
            s = convergence(runs, case, group)
            if not s["runs"] and not s["failed"]:
                continue
            unit = " m" if group == "space" else ""
            hs = ", ".join(f"{h:.3g}{unit}" for h in s["h"])
            fails = "; ".join(f"{r.label}: {r.note}" for r in s["failed"]) or "0"
            if case == "wu2008":
                errs = [f"{100 * r.error:.1f} %" for r in s["runs"]]
                conv_rows.append(f"| {case} | {group} | {hs} | mean {', '.join(errs)} | | | | | | | {fails} |")
                continue
            e = {p: ", ".join(f"{100 * x:+.2f} %" for x in s["parts"].get(p, [])) for p in ("R", "w0")}
            mono = ", ".join(f"{p} {'yes' if s['monotone'].get(p) else 'no'}" for p in ("R", "w0"))
            conv_rows.append(f"| {case} | {group} | {hs} | {e['R']} | {e['w0']} | "
                             f"{s['order'].get('R', math.nan):.2f} | {s['order'].get('w0', math.nan):.2f} | "
                             f"{s['self_order'].get('R', math.nan):.2f} | {s['self_order'].get('w0', math.nan):.2f} | "
                             f"{mono} | {fails} |")
    if conv_rows:
        L += ["", "## Convergence of the fracture engine", "",
              "Space: cell sizes at time-step relaxation 0.25; time: relaxation lambda (dt = lambda min(dx, dz) / "
              "max V_T, Eq. 35) at the scene's cells. `order` is the slope of log|error vs Dontsov| against "
              "log h; `self-order` the slope of log|q(h) / q(h_finest) - 1| (Richardson-style, against the finest "
              "run of the series), which isolates the discretisation error from the one of the other knob. The "
              "reference is itself approximate: published M-vertex prefactors differ by ~0.5 % in R and w(0) "
              "(0.6955, 0.6976, 0.6944 in Savitski & Detournay 2002, PyFrac and Dontsov's code), so errors under "
              "~1 % are not resolved.", "",
              "| case | series | h | R error | w(0) error | order R | order w(0) | self-order R | self-order w(0) "
              "| monotone | failed |", "|---|---|---|---|---|---|---|---|---|---|---|"]
        L += conv_rows
        L += ["", "A series whose error changes sign or does not fall monotonically (monotone: no) has errors of "
              "different origins cancelling (e.g. the front's sub-cell position against the tip asymptote), and "
              "its fitted order against the reference means little; the self-order is then the better guide.", ""]
    for case in FIELD_CASES:
        rows = parcel_study(runs, case)
        if not rows:
            continue
        top = rows[-1]
        L += [f"## Propped area against parcel count ({case}, scaled demo)", "",
              "Other knobs at the scene's values; seeds `[run] seed`. Spread = sample standard deviation over the "
              "seeds. `diff` is the mean's difference from the mean at the most parcels.", "",
              "| parcels per cell | seeds | parcels at end | propped area mean [m^2] | std | min | max | diff | "
              "propped fraction | CPU s |", "|---|---|---|---|---|---|---|---|---|---|"]
        for r in rows:
            L.append(f"| {r['ppc']} | {r['seeds']} | {r['parcels']:.0f} | {r['mean']:.0f} | {_fmt(r['std'], False)} | "
                     f"{r['min']:.0f} | {r['max']:.0f} | {_fmt(r['mean'] / top['mean'] - 1 if top['mean'] else math.nan)} | "
                     f"{_fmt(r['fraction'])} | {r['cpu']:.1f} |")
        L.append("")
    L += ["## All runs", ""]
    for case, case_rows in by_case.items():
        ok = [r for r in case_rows if np.isfinite(r.error) and np.isfinite(r.cpu)]
        front = [ok[i] for i in pareto_front([(r.cpu, r.error) for r in ok])]
        L += [f"### {case}", "", "Pareto front (cheapest first): " +
              " -> ".join(f"{r.label} ({_fmt(r.error)}, {r.cpu:.2f} s)" for r in front), ""]
        L += _case_table(case_rows) + [""]
    doc.write_text("\n".join(L) + "\n")
    return [doc, pareto, conv]
