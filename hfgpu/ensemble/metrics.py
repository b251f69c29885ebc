"""The metrics of one member, read from its results file (names: hfgpu.ensemble.sweep_file.METRIC_NAMES).

Where each comes from (``/summary`` keys carry a ``fracture_`` prefix in coupled runs; NaN where a member's
physics lacks it, e.g. proppant metrics of a fracture-only scene):

* ``created_area`` [m^2]: the fracture's final ``area``; proppant-only scenes: the open cells' area
  (hfgpu.propped.created_area);
* ``propped_area`` [m^2], ``propped_fraction`` [-]: hfgpu.propped.propped_summary at the last proppant snapshot
  (one packed grain layer; the fraction is of that grid's created area);
* ``fracture_height``, ``fracture_length`` [m]: the final ``height`` and ``length``;
* ``net_pressure_end`` [Pa]: the summary's ``net_pressure_end``, the last fracture step's net pressure at the
  injection cell (/fracture/balance);
* ``efficiency`` [-]: the summary's fluid efficiency, stored / injected volume;
* ``screened_out`` [-]: 1 when proppant was held back at the inlets (``proppant_screened_out`` > 0), else 0.

``propped_map`` gives the member's propped cells (last proppant snapshot) for the ensemble's probability maps.
"""

from __future__ import annotations

import numpy as np

from ..records import GridFrame

NAN = float("nan")
#: The unit of each metric (SI; "-" for a ratio or a flag).
UNITS = {"created_area": "m^2", "propped_area": "m^2", "propped_fraction": "-", "fracture_height": "m",
         "fracture_length": "m", "net_pressure_end": "Pa", "efficiency": "-", "screened_out": "-"}


def member_metrics(results) -> dict[str, float]:
    """Every metric of an opened, complete results file (NaN where the run's physics has none)."""
    s = results.summary

    def fracture(name: str) -> float:
        return float(s.get(name, s.get(f"fracture_{name}", NAN)))

    out = {"created_area": fracture("area"), "fracture_height": fracture("height"),
           "fracture_length": fracture("length"), "efficiency": float(s.get("efficiency", NAN)),
           "net_pressure_end": float(s.get("net_pressure_end", NAN)), "propped_area": NAN, "propped_fraction": NAN,
           "screened_out": NAN}
    scene = results.scene
    if len(results.proppant_snapshots):
        from ..propped import propped_summary

        propped = propped_summary(results)
        out.update(propped_area=propped["propped_area"], propped_fraction=propped["propped_fraction"],
                   screened_out=1.0 if float(s.get("proppant_screened_out", 0.0)) > 0.0 else 0.0)
        if scene.rock is None:
            out["created_area"] = propped["created_area"]
    return out


def propped_map(results) -> tuple[GridFrame, np.ndarray] | None:
    """(frame, propped cells as bool (nz, nx)) at the last proppant snapshot; None without proppant."""
    if not len(results.proppant_snapshots):
        return None
    from ..propped import propped_cells

    snap = results.proppant_snapshots[-1]
    return snap.frame, propped_cells(snap, results.scene.proppant.params.theta_cp)
