"""Online controllers: steering (paper eq. 38), longitudinal PIDs (sec. 9), path references."""

from eoam_sumo.control.longitudinal import LongitudinalController, LongitudinalGains, Pid
from eoam_sumo.control.paths import PathPoint, PathReference, QuinticShift
from eoam_sumo.control.steering import (
    SteeringCommand,
    SteeringController,
    SteeringGains,
    understeer_gradient,
)

__all__ = [
    "LongitudinalController",
    "LongitudinalGains",
    "PathPoint",
    "PathReference",
    "Pid",
    "QuinticShift",
    "SteeringCommand",
    "SteeringController",
    "SteeringGains",
    "understeer_gradient",
]
