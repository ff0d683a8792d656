"""A SUMO scenario as files: the ``.sumocfg`` and what it names (network, routes, additional
files), checked before SUMO starts; the run's overrides; the vehicles whose stop is scripted.

Modules: ``files`` (sumocfg, vehicles, its end), ``network`` (opposite lanes, lane checks),
``routes`` (the ego's route as written: an oncoming car needs a lane beside it),
``overrides`` (:class:`ScenarioOverrides`), ``stops`` (scripted emergency stops),
``xmlread`` and ``values`` (reading and checking helpers).
"""

from eoam_sumo.sim.scenario.files import ScenarioFiles, VehicleSpec, check_scenario
from eoam_sumo.sim.scenario.overrides import ScenarioOverrides
from eoam_sumo.sim.scenario.stops import DECEL_KEY, HOLD_KEY, ROLE_KEY, scripted_stops

__all__ = [
    "DECEL_KEY",
    "HOLD_KEY",
    "ROLE_KEY",
    "ScenarioFiles",
    "ScenarioOverrides",
    "VehicleSpec",
    "check_scenario",
    "scripted_stops",
]
