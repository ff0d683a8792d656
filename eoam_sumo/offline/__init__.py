"""Offline EOAM design (paper secs. 4-8): lane-change paths, inverse dynamics, the optimal
longitudinal profile, DMM phase boundaries and the 3D lookup tables.

The run-time part (``LookupTables``, ``PhaseBoundaries``) needs only numpy; ``build_tables``
(CasADi, SciPy) is imported on first use.
"""

from eoam_sumo.offline.boundaries import max_decel_no_lock_mps2
from eoam_sumo.offline.design import DesignSettings
from eoam_sumo.offline.tables import (
    Boundary,
    LookupTables,
    PhaseBoundaries,
    Trajectory,
    TrajectoryPoint,
    default_tables_dir,
)

__all__ = [
    "Boundary",
    "DesignSettings",
    "LookupTables",
    "PhaseBoundaries",
    "Trajectory",
    "TrajectoryPoint",
    "build_tables",
    "default_tables_dir",
    "max_decel_no_lock_mps2",
]


def __getattr__(name):
    if name == "build_tables":
        from eoam_sumo.offline.build import build_tables

        return build_tables
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
