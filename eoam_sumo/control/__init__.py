"""Online controllers: steering (paper eq. 38), longitudinal PIDs (sec. 9), path references."""

from eoam_sumo.control.longitudinal import LongitudinalController, LongitudinalGains, Pid
from eoam_sumo.control.reference import PathReference, QuinticShift
from eoam_sumo.control.steering import SteeringController, SteeringGains, understeer_gradient

__all__ = [
    "LongitudinalController",
    "LongitudinalGains",
    "PathReference",
    "Pid",
    "QuinticShift",
    "SteeringController",
    "SteeringGains",
    "understeer_gradient",
]
