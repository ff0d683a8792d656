"""Online controllers: steering (paper eq. 38) and longitudinal PIDs (sec. 9)."""

from eoam_sumo.control.longitudinal import LongitudinalController, LongitudinalGains, Pid
from eoam_sumo.control.steering import (
    SteeringCommand,
    SteeringController,
    SteeringGains,
    understeer_gradient,
)

__all__ = [
    "LongitudinalController",
    "LongitudinalGains",
    "Pid",
    "SteeringCommand",
    "SteeringController",
    "SteeringGains",
    "understeer_gradient",
]
