"""``eoam-sumo run FILE.xosc``: read, compile, convert the road, write SUMO files, run."""

from __future__ import annotations

import os
from dataclasses import dataclass, replace
from pathlib import Path

from eoam_sumo.openscenario.checks import check_places
from eoam_sumo.openscenario.compile import compile_plan
from eoam_sumo.openscenario.engine import Storyboard
from eoam_sumo.openscenario.geometry import LaneMap
from eoam_sumo.openscenario.model import Plan
from eoam_sumo.openscenario.reader import Scenario, read_scenario
from eoam_sumo.openscenario.road import check_road, convert, wide_lanes
from eoam_sumo.openscenario.sumofiles import write_sumo

CACHE_ENV = "EOAM_SUMO_CACHE_DIR"


@dataclass(frozen=True)
class Loaded:
    """A scenario read, compiled and its road converted: ready to write and run."""

    scenario: Scenario
    plan: Plan
    net: Path
    lanes: LaneMap


def road_cache() -> Path:
    """Where converted roads are kept: ``$EOAM_SUMO_CACHE_DIR``, else the user's cache."""
    if os.environ.get(CACHE_ENV):
        return Path(os.environ[CACHE_ENV]) / "opendrive"
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "eoam-sumo" / "opendrive"


def load(xosc: Path, params: dict[str, str], ego: str | None = None) -> Loaded:
    """Everything outside the subset is refused here, before any run or output."""
    scenario = read_scenario(xosc, params)
    plan = compile_plan(scenario, ego)
    plan.notes += wide_lanes(scenario.road)
    net, lanes = road_map(scenario.road)
    check_places(scenario.root, plan.places, lanes)
    return Loaded(scenario, plan, net, lanes)


def road_map(road: Path) -> tuple[Path, LaneMap]:
    """The road checked (left-hand traffic refused), converted (cached) and mapped."""
    check_road(road)
    net = convert(road, road_cache())
    return net, LaneMap(net, road)


def write_scenario(loaded: Loaded, folder: Path) -> Path:
    """The SUMO files of ``loaded`` in ``folder``; the .sumocfg."""
    return write_sumo(loaded.plan, loaded.net, loaded.lanes, folder, loaded.scenario.path)


def run_loaded(
    loaded: Loaded, out: Path, settings, mu: float | None = None, timeseries: str = "csv"
) -> dict:
    """Run with the ordinary co-simulation (outputs as any run, the SUMO files in
    ``out/scenario``); the summary."""
    from eoam_sumo.sim.cosim import CoSimulation
    from eoam_sumo.sim.runlog import write_run
    from eoam_sumo.sim.scenario import ScenarioOverrides

    cfg = write_scenario(loaded, out / "scenario")
    settings = replace(settings, ego_id="ego")
    board = Storyboard(loaded.scenario.root, loaded.plan, loaded.lanes, loaded.scenario.parameters)
    sim = CoSimulation(cfg, ScenarioOverrides(mu=mu), settings, observers=(board,))
    summary, log = sim.run()
    summary = {**summary, "storyboard_ended": board.ended_by_storyboard}
    write_run(out, summary, log, timeseries, sim.traffic, sim.session.ego_lane_centreline())
    return summary
