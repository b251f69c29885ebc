"""The metrics of one member, read from its results file (names: hfgpu.ensemble.sweep_file.METRIC_NAMES).

Where each comes from (``/summary`` keys carry a ``fracture_`` prefix in coupled runs; NaN where a member's
physics lacks it, e.g. proppant metrics of a fracture-only scene):

* ``created_area``, ``propped_area``, ``propped_area_in_place`` [m^2], ``propped_fraction`` [-]: the run summary's
  numbers, hfgpu.propped.headline_propped: the propped area after closure (the summary's "propped area"), the
  one-layer rule with the grains in place, the fraction propped after closure of the created area (the
  fracture's final ``area``, one face; the open cells of the proppant grid in a proppant-only scene);
* ``fracture_height``, ``fracture_length`` [m]: the final ``height`` and ``length``;
* ``net_pressure_end`` [Pa]: the summary's ``net_pressure_end``, the last fracture step's net pressure at the
  injection cell (/fracture/balance);
* ``efficiency`` [-]: the summary's fluid efficiency, stored / injected volume;
* ``screened_out`` [-]: 1 when proppant was held back at the inlets (``proppant_screened_out`` > 0), else 0;
* ``cluster_area_uniformity`` [-]: a stage of several clusters (``[completion]``): the smallest cluster's created
  area over the clusters' mean (the summary's ``cluster_<i>_area``; 1: every cluster alike), NaN for one fracture;
* ``cluster_propped_uniformity`` [-]: the same of the clusters' propped areas after closure (the summary's
  ``cluster_<i>_closure_propped_area``, a stage with proppant: hfgpu.coupled_stage), NaN without them.

``propped_map`` gives the member's cells propped after closure (``/closure`` ``propped``, the cells the
``propped_area`` counts) for the ensemble's probability maps.
"""

from __future__ import annotations

import numpy as np

from ..records import GridFrame

NAN = float("nan")
#: The unit of each metric (SI; "-" for a ratio or a flag).
UNITS = {"created_area": "m^2", "propped_area": "m^2", "propped_area_in_place": "m^2", "propped_fraction": "-",
         "fracture_height": "m", "fracture_length": "m", "net_pressure_end": "Pa", "efficiency": "-",
         "screened_out": "-", "cluster_area_uniformity": "-", "cluster_propped_uniformity": "-"}


def member_metrics(results) -> dict[str, float]:
    """Every metric of an opened, complete results file (NaN where the run's physics has none)."""
    s = results.summary

    def fracture(name: str) -> float:
        return float(s.get(name, s.get(f"fracture_{name}", NAN)))

    out = {"created_area": fracture("area"), "fracture_height": fracture("height"),
           "fracture_length": fracture("length"), "efficiency": float(s.get("efficiency", NAN)),
           "net_pressure_end": float(s.get("net_pressure_end", NAN)), "propped_area": NAN, "propped_fraction": NAN,
           "propped_area_in_place": NAN, "screened_out": NAN, "cluster_area_uniformity": NAN,
           "cluster_propped_uniformity": NAN}
    for metric, key in (("cluster_area_uniformity", "area"), ("cluster_propped_uniformity", "closure_propped_area")):
        clusters: list[float] = []
        while f"cluster_{len(clusters)}_{key}" in s:
            clusters.append(float(s[f"cluster_{len(clusters)}_{key}"]))
        if len(clusters) > 1 and np.mean(clusters) > 0.0:
            out[metric] = min(clusters) / float(np.mean(clusters))
    if len(results.proppant_snapshots):
        from ..propped import headline_propped

        propped = headline_propped(results)
        out.update({k: propped[k] for k in ("created_area", "propped_area", "propped_fraction",
                                            "propped_area_in_place")},
                   screened_out=1.0 if float(s.get("proppant_screened_out", 0.0)) > 0.0 else 0.0)
    return out


def propped_map(results) -> tuple[GridFrame, np.ndarray] | None:
    """(frame, cells propped after closure as bool (nz, nx)); None without proppant."""
    if not len(results.proppant_snapshots):
        return None
    from ..closure.conductivity import closure_of

    closure = closure_of(results)
    return closure.frame, np.asarray(closure.fields["propped"]) > 0
