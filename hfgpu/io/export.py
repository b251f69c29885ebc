"""``hfgpu export RESULTS.h5 --format stimplan-xml|vtk|csv --out FILE [--units SI|field]`` (docs/cli.md)."""

from __future__ import annotations

from pathlib import Path

from ..closure.conductivity import closure_of
from ..errors import HfgpuError
from .export_csv import write_csv
from .export_map import export_map
from .export_stimplan import write_stimplan
from .export_vtk import write_vtk
from .results import Results, open_results

FORMATS = ("stimplan-xml", "vtk", "csv")


def output_units(results: Results) -> str:
    """The stored scene's ``[output] units`` ("SI" when the scene does not parse)."""
    try:
        return results.scene.output.units
    except HfgpuError:
        return "SI"


def export(path: str | Path, fmt: str, out: str | Path, units: str | None = None) -> list[Path]:
    """Export the results file ``path`` as ``fmt`` to ``out`` in ``units`` ("SI" or "field"; default the
    scene's ``[output] units``); return the files written. StimPlan and CSV write the map of
    :func:`hfgpu.io.export_map.export_map` (the created fracture and, with proppant, the closure map: the file's
    ``/closure`` group, or computed from its proppant snapshots, :func:`hfgpu.closure.conductivity.closure_of`);
    a stage with proppant writes one file per cluster, ``<stem>_cluster<i><suffix>`` (i from 1), and VTK its
    clusters side by side on the proppant grid (hfgpu.stage_blocks)."""
    if fmt not in FORMATS:
        raise HfgpuError(f"export format {fmt!r}: allowed {', '.join(FORMATS)}")
    results = open_results(path)
    system = units or output_units(results)
    out = Path(out)
    if not out.parent.is_dir():
        raise HfgpuError(f"cannot write '{out}': the folder '{out.parent}' does not exist")
    if fmt == "vtk":
        has_closure = len(results.proppant_snapshots) and (results.closure is not None or _scene_has_closure(results))
        return write_vtk(results, closure_of(results) if has_closure else None, out)
    writer = write_stimplan if fmt == "stimplan-xml" else write_csv
    clusters = len(results.stage_snapshots) if len(results.proppant_snapshots) else 0
    if not clusters:
        return writer(results, export_map(results), out, system)
    files = []
    for i in range(clusters):   # a stage with proppant: one fracture per file, as the receiving tools read them
        view = results.cluster(i)
        files += writer(view, export_map(view, cluster=i), out.with_name(f"{out.stem}_cluster{i + 1}{out.suffix}"),
                        system)
    return files


def _scene_has_closure(results: Results) -> bool:
    try:
        return results.scene.closure is not None
    except HfgpuError:
        return False
