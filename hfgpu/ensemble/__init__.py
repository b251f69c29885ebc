"""Ensembles and sensitivity studies: a sweep file varies scene keys, Dask runs the members (docs/ensembles.md).

Modules: ``sweep_file`` (the sweep file's keys, read and checked), ``design`` (sampling designs and inverse
CDFs), ``members`` (member scenes as TOML, validated), ``metrics`` (a member's metrics from its results file),
``execute`` (Dask submission, faults, resume), ``summary`` (summary.csv, percentiles, probability maps,
ensemble.h5), ``table_units`` (each column's unit in the base scene's unit system), ``plots`` (the figures of
``hfgpu plot DIR``).
"""

from .execute import MEMBER_RETRIES, sweep
from .members import MemberError
from .sweep_file import SweepError, load_sweep

__all__ = ["MEMBER_RETRIES", "MemberError", "SweepError", "load_sweep", "sweep"]
