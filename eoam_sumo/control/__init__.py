"""Online controllers: steering (paper eq. 38) and longitudinal PIDs (sec. 9)."""

from eoam_sumo.control.longitudinal import (
    LongitudinalController,
    LongitudinalGains,
    Pid,
    equivalent_mass_kg,
)
from eoam_sumo.control.steering import (
    SteeringCommand,
    SteeringController,
    SteeringGains,
    axle_cornering_stiffness_npr,
    understeer_gradient,
)

__all__ = [
    "LongitudinalController",
    "LongitudinalGains",
    "Pid",
    "SteeringCommand",
    "SteeringController",
    "SteeringGains",
    "axle_cornering_stiffness_npr",
    "equivalent_mass_kg",
    "understeer_gradient",
]
