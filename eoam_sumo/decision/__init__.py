"""Online decision logic: DMM phase-diagram sectors (paper sec. 5-6) and modes 0-5 (sec. 3.2)."""

from eoam_sumo.decision.dmm import (
    SECTOR_ORDER,
    Action,
    BoundaryCurve,
    BoundaryRow,
    Sector,
    classify,
    dmm_sector,
)
from eoam_sumo.decision.modes import Mode, next_mode

__all__ = [
    "SECTOR_ORDER",
    "Action",
    "BoundaryCurve",
    "BoundaryRow",
    "Mode",
    "Sector",
    "classify",
    "dmm_sector",
    "next_mode",
]
