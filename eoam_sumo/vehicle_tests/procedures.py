"""The standard tests by their command-line names, each a pure function
``(params, options, vehicle=None) -> VehicleTestResult``."""

from eoam_sumo.vehicle_tests.brake_tests import brake, brake_ramp
from eoam_sumo.vehicle_tests.common import VehicleTestOptions, VehicleTestResult
from eoam_sumo.vehicle_tests.sine_with_dwell import sine_with_dwell
from eoam_sumo.vehicle_tests.steer_tests import ramp_steer, step_steer
from eoam_sumo.vehicle_tests.turn_brake import brake_in_turn

TESTS = {
    "sine-with-dwell": sine_with_dwell,
    "brake": brake,
    "brake-ramp": brake_ramp,
    "ramp-steer": ramp_steer,
    "step-steer": step_steer,
    "brake-in-turn": brake_in_turn,
}

__all__ = ["TESTS", "VehicleTestOptions", "VehicleTestResult"]
