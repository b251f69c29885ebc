"""The closure map of a results file: propped width, closure stress, pack permeability and conductivity per cell
of the proppant grid, and its scalars (docs/closure.md, results-format.md ``/closure/``).

    C = k w_p                 [m^3 in SI; md ft in field units]
    sigma_c(z) = sigma_0(z) - p_r(z)        (the layer's minimum stress less its pore pressure), or the scene's
                                            uniform ``[closure] closure_stress``

k per cell (:mod:`.permeability`): without any conductivity table in the scene, Kozeny-Carman with the cell's
Sauter mean diameter; with tables, each class present gets its table's k(sigma_c) (Kozeny-Carman on its own
Sauter diameter in the cell where it has none) and the cell's k is their volume-weighted geometric mean
exp(sum x_c ln k_c) (x_c: class c's share of the cell's solids; the geometric mean of a random mixture,
Warren & Price 1961). The per-class ``conductivity_factor`` f_c multiplies k by exp(sum x_c ln f_c).

Scalars (one face of the fracture, both wings): ``propped_area`` A_p = dx dz (number of propped cells);
``propped_half_length`` x_p = half the propped length, dx times the number of grid columns holding a propped
cell, / 2; ``propped_height`` h_p = A_p / (2 x_p), the mean propped height over those columns (A_p = 2 x_p h_p);
``mean_conductivity`` = the area-weighted mean of C over the propped cells; ``fcd`` = mean C / (k_f x_p), the
dimensionless fracture conductivity (Cinco-Ley & Samaniego 1981) for the formation permeability k_f of
``[closure] formation_permeability`` (NaN without it).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import HfgpuError
from ..records import GridFrame, ProppantSnapshot
from ..stage_blocks import cluster_view, clusters_of
from .config import ClosureConfig
from .pack import Pack, propped_width, settle
from .permeability import kozeny_carman, table_permeability

#: The scalar attributes of ``/closure`` and their SI units.
SCALARS = {"time": "s", "propped_area": "m^2", "propped_half_length": "m", "propped_height": "m",
           "mean_conductivity": "m^3", "fcd": "1", "pack_solid_fraction": "1", "formation_permeability": "m^2"}
#: The scalars given per cluster of a stage (``cluster_<i>_closure_<name>`` in ``/summary``).
CLUSTER_SCALARS = ("propped_area", "propped_half_length", "propped_height", "mean_conductivity", "fcd")


@dataclass(frozen=True)
class ClosureMap:
    """The closure of one proppant snapshot: ``frame`` (the proppant grid's), ``fields`` ((nz, nx) arrays
    ``propped_width`` [m], ``conductivity`` [m^3], ``closure_stress`` [Pa], ``permeability`` [m^2], ``solid_volume``
    [m^3], ``sauter_diameter`` [m], ``propped`` [0/1]), ``scalars`` (:data:`SCALARS`, SI) and ``labels``
    (``settling``, ``permeability_model``)."""

    frame: GridFrame
    fields: dict[str, np.ndarray] = field(repr=False)
    scalars: dict[str, float]
    labels: dict[str, str]
    clusters: tuple[dict[str, float], ...] = ()

    def summary(self) -> dict[str, Any]:
        """The scalars and labels prefixed ``closure_`` (for ``/summary``), and a stage's :meth:`cluster_summary`."""
        return {**{f"closure_{k}": v for k, v in {**self.scalars, **self.labels}.items()}, **self.cluster_summary()}

    def cluster_summary(self) -> dict[str, float]:
        """A stage's per-cluster scalars as ``cluster_<i>_closure_<name>`` (CLUSTER_SCALARS; none for one
        fracture)."""
        return {f"cluster_{i}_closure_{k}": c[k] for i, c in enumerate(self.clusters) for k in CLUSTER_SCALARS}


def closure_stress(scene: Any, frame: GridFrame, shape: tuple[int, int]) -> np.ndarray:
    """sigma_c [Pa] per cell: ``[closure] closure_stress`` where given, else sigma_0(z) - p_r(z) of ``[rock]``;
    NaN where the scene gives neither (Kozeny-Carman does not need it)."""
    nz, nx = shape
    cfg: ClosureConfig = scene.closure
    if cfg.closure_stress is not None:
        return np.full(shape, cfg.closure_stress)
    if scene.rock is None:
        return np.full(shape, np.nan)
    _, z = frame.centres(nz, nx)
    column = scene.rock.min_stress_at(z) - scene.rock.pore_pressure_at(z)
    return np.repeat(column[:, None], nx, axis=1)


def permeability(pack: Pack, classes: tuple, stress: np.ndarray, pack_fraction: float) -> tuple[np.ndarray, str]:
    """(k [m^2] per cell, model name) for the pack's grain mix (see the module docstring); 0 in empty cells."""
    porosity = 1.0 - pack_fraction
    solid = pack.solid
    share = np.divide(pack.volume, solid, out=np.zeros(pack.volume.shape), where=solid > 0.0)
    log_factor = sum(share[c] * math.log(cls.closure.factor) for c, cls in enumerate(classes))
    if all(cls.closure.table is None for cls in classes):
        k, model = kozeny_carman(pack.sauter_diameter(), porosity), "kozeny-carman"
    else:
        log_k = np.zeros(solid.shape)
        for c, cls in enumerate(classes):
            present = share[c] > 0.0
            if cls.closure.table is not None:
                k_c = table_permeability(cls.closure.table, stress[present], cls.density, cls.closure.loading,
                                         pack_fraction)
            else:
                d32 = pack.volume[c][present] / pack.volume_per_diameter[c][present]
                k_c = kozeny_carman(d32, porosity)
            log_k[present] += share[c][present] * np.log(k_c)
        k, model = np.exp(log_k), "table"
    return np.where(solid > 0.0, k * np.exp(log_factor), 0.0), model


def close(snap: ProppantSnapshot, scene: Any) -> ClosureMap:
    """The :class:`ClosureMap` of proppant snapshot ``snap`` for ``scene`` (with its ``closure`` config). A stage's
    snapshot (its clusters side by side, hfgpu.stage_blocks) is closed whole and cluster by cluster: the map and
    ``propped_area`` and ``mean_conductivity`` are the stage's; ``propped_half_length``, ``propped_height`` and
    ``fcd`` those of the cluster with the largest propped area (a half-length over clusters side by side means
    nothing); ``clusters`` holds every cluster's scalars."""
    n = clusters_of(snap)
    if not n:
        return _close(snap, scene)
    whole = _close(snap, scene)
    parts = [_close(cluster_view(snap, i), scene).scalars for i in range(n)]
    lead = max(parts, key=lambda c: c["propped_area"])
    scalars = {**whole.scalars, **{k: lead[k] for k in ("propped_half_length", "propped_height", "fcd")}}
    return dataclasses.replace(whole, scalars=scalars, clusters=tuple(parts))


def _close(snap: ProppantSnapshot, scene: Any) -> ClosureMap:
    """:func:`close` of one fracture's snapshot."""
    cfg: ClosureConfig = scene.closure
    classes = scene.proppant.classes
    frame, width = snap.frame, np.asarray(snap.grid["width"], dtype=np.float64)
    area = frame.dx * frame.dz
    pack = settle(snap, len(classes), cfg.settling, cfg.pack_solid_fraction)
    w_p, propped = propped_width(pack, area, cfg.pack_solid_fraction, cfg.layers, cfg.embedment, width)
    stress = closure_stress(scene, frame, width.shape)
    k, model = permeability(pack, classes, stress, cfg.pack_solid_fraction)
    k = np.where(propped, k, 0.0)
    conductivity = k * w_p
    fields = dict(propped_width=w_p, conductivity=conductivity, closure_stress=stress, permeability=k,
                  solid_volume=pack.solid, sauter_diameter=pack.sauter_diameter(), propped=propped.astype(np.int8))
    n_propped = int(propped.sum())
    columns = int(propped.any(axis=0).sum())
    half_length = 0.5 * columns * frame.dx
    mean_c = float(conductivity[propped].mean()) if n_propped else 0.0
    k_f = cfg.formation_permeability
    scalars = dict(time=float(snap.time), propped_area=n_propped * area, propped_half_length=half_length,
                   propped_height=n_propped * area / (2.0 * half_length) if columns else 0.0,
                   mean_conductivity=mean_c,
                   fcd=mean_c / (k_f * half_length) if k_f is not None and columns else math.nan,
                   pack_solid_fraction=cfg.pack_solid_fraction,
                   formation_permeability=k_f if k_f is not None else math.nan)
    return ClosureMap(frame=frame, fields=fields, scalars=scalars,
                      labels=dict(settling=cfg.settling, permeability_model=model))


def closure_of(results: Any, scene: Any = None) -> ClosureMap:
    """The closure map of a results file (:class:`hfgpu.io.results.Results`): its ``/closure`` group when it
    has one, else computed from its proppant snapshot at ``[closure] time`` (default the last) with ``scene``
    (default the stored scene)."""
    stored = results.closure
    if stored is not None:
        return ClosureMap(frame=stored["frame"], fields=stored["fields"],
                          scalars={k: float(stored["attrs"][k]) for k in SCALARS},
                          labels={k: str(stored["attrs"][k]) for k in ("settling", "permeability_model")})
    snaps = results.proppant_snapshots
    if not len(snaps):
        raise HfgpuError(f"'{results.path}' holds no proppant snapshot to close the fracture on")
    scene = results.scene if scene is None else scene
    if scene.closure is None:
        raise HfgpuError(f"'{results.path}': its scene has no proppant, so no closure")
    time = scene.closure.time
    return close(snaps[-1] if time is None else snaps.at(time), scene)
