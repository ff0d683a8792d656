"""``eoam-sumo run FILE.xosc``: read, compile, convert the road, write SUMO files, run."""

from __future__ import annotations

import os
import re
import sys
from dataclasses import dataclass, replace
from pathlib import Path

from eoam_sumo.openscenario.checks import check_places
from eoam_sumo.openscenario.compile import compile_plan
from eoam_sumo.openscenario.departures import check_departures
from eoam_sumo.openscenario.engine import Storyboard
from eoam_sumo.openscenario.geometry import LaneMap
from eoam_sumo.openscenario.model import Plan
from eoam_sumo.openscenario.reader import Scenario, read_scenario
from eoam_sumo.openscenario.road import check_road, convert, wide_lanes
from eoam_sumo.openscenario.story import COMPLETE
from eoam_sumo.openscenario.sumofiles import SUMOCFG, ego_offset_notes, write_sumo

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


def load(
    xosc: Path,
    params: dict[str, str],
    ego: str | None = None,
    ego_range_mps: tuple[float, float] | None = None,
) -> Loaded:
    """Everything outside the subset is refused here, before any run or output (the ego's
    departure speed outside ``ego_range_mps``, the tables' design range, too)."""
    scenario = read_scenario(xosc, params)
    plan = compile_plan(scenario, ego)
    check_departures(scenario.root, plan, ego_range_mps)
    plan.notes += wide_lanes(scenario.road)
    net, lanes = road_map(scenario.road)
    check_places(scenario.root, plan.places, lanes)
    plan.notes += ego_offset_notes(plan, lanes)
    return Loaded(scenario, plan, net, lanes)


def ego_speed_range_mps(settings) -> tuple[float, float]:
    """The ego's departure speeds the run's lookup tables cover (``LookupTables.check_run``):
    the tables of ``settings``' vehicle under its ``tables_dir``."""
    from eoam_sumo.sim.vehicle import vehicle_tables

    tables = vehicle_tables(settings.vehicle_id, settings.vehicle, settings.tables_dir)
    return tables.entry_speed_range_mps()


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

    settings = replace(settings, ego_id="ego")
    board = Storyboard(loaded.scenario.root, loaded.plan, loaded.lanes, loaded.scenario.parameters)
    cfg = out / "scenario" / SUMOCFG
    # the tables, friction and the ego's speed checked before anything is written
    sim = CoSimulation(cfg, ScenarioOverrides(mu=mu), settings, observers=(board,))
    check_departures(loaded.scenario.root, loaded.plan, sim.tables.entry_speed_range_mps())
    write_scenario(loaded, cfg.parent)
    summary, log = sim.run()
    summary = {
        **summary,
        "storyboard_ended": board.ended_by_storyboard,
        "net_offset_m": net_offset_m(loaded.net),
    }
    write_run(out, summary, log, timeseries, sim.traffic, sim.session.ego_lane_centreline())
    if summary.get("end_cause") == "time_limit" and _unfinished(board):
        print(f"eoam-sumo: {loaded.scenario.path.name}: stopped at --max-time-s "
              f"{settings.max_time_s:g} before the storyboard's end", file=sys.stderr)  # fmt: skip
    return summary


def _unfinished(board: Storyboard) -> bool:
    """Whether the storyboard had more to run: its StopTrigger not fired, or a story not
    complete (an event still waiting for its trigger)."""
    if board.ended_by_storyboard:
        return False
    return board.stop is not None or any(s.state != COMPLETE for s in board.stories)


def net_offset_m(net: Path) -> list[float]:
    """netconvert's ``netOffset`` of the converted road [x, y]: SUMO's coordinates (every
    output's x, y) are the OpenDRIVE road's plus it."""
    with net.open("rb") as fh:
        head = fh.read(65536).decode("utf-8", "replace")
    found = re.search(r'<location[^>]*\bnetOffset="([^"]*)"', head)
    if found is None:
        return [0.0, 0.0]
    x, y = (float(v) for v in found.group(1).split(",")[:2])
    return [x, y]
