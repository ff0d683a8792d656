"""The ego vehicle plant: a nonlinear single-track model with wheel spin, Magic Formula tyres
per wheel with load transfer, hydraulic brakes, ABS, ESC, drivetrains, drag and actuator lags
(docs/chassis.md), integrated by a fixed-step explicit midpoint rule.

``Plant`` is the fast online path (compiled C, one call per co-simulation step);
``ReferencePlant`` evaluates the same model with Python floats; ``rhs`` / ``outputs`` with
``CASADI_OPS`` give the same model as CasADi expressions for the offline optimiser.
"""

from eoam_sumo.plant.compiled import Plant
from eoam_sumo.plant.model import INPUT_NAMES, OUTPUT_NAMES, STATE_NAMES, outputs, rhs
from eoam_sumo.plant.ops import CASADI_OPS, FLOAT_OPS
from eoam_sumo.plant.reference import ReferencePlant
from eoam_sumo.plant.stepping import cruise_drive_force_n, initial_state

__all__ = [
    "CASADI_OPS",
    "FLOAT_OPS",
    "INPUT_NAMES",
    "OUTPUT_NAMES",
    "STATE_NAMES",
    "Plant",
    "ReferencePlant",
    "cruise_drive_force_n",
    "initial_state",
    "outputs",
    "rhs",
]
