"""``eoam-sumo run FILE.xosc``: read, compile, convert the road, write SUMO files, run."""

from __future__ import annotations

import os
from dataclasses import dataclass, replace
from pathlib import Path

from eoam_sumo.openscenario.compile import compile_plan
from eoam_sumo.openscenario.model import Plan
from eoam_sumo.openscenario.reader import Scenario, read_scenario
from eoam_sumo.openscenario.road import convert
from eoam_sumo.openscenario.sumofiles import DEPART_S, write_sumo

CACHE_ENV = "EOAM_SUMO_CACHE_DIR"


@dataclass(frozen=True)
class Loaded:
    """A scenario read, compiled and its road converted: ready to write and run."""

    scenario: Scenario
    plan: Plan
    net: Path


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
    return Loaded(scenario, plan, convert(scenario.road, road_cache()))


def write_scenario(loaded: Loaded, folder: Path) -> Path:
    """The SUMO files of ``loaded`` in ``folder``; the .sumocfg."""
    return write_sumo(loaded.plan, loaded.net, loaded.scenario.road, folder, loaded.scenario.path)


def run_loaded(loaded: Loaded, out: Path, settings, mu: float | None = None) -> dict:
    """Run with the ordinary co-simulation (outputs as any run, the SUMO files in
    ``out/scenario``); the summary."""
    from eoam_sumo.sim.cosim import run_case
    from eoam_sumo.sim.scenario import ScenarioOverrides

    cfg = write_scenario(loaded, out / "scenario")
    settings = replace(settings, ego_id="ego")
    end = loaded.plan.end_s
    if end is not None:
        settings = replace(settings, max_time_s=min(settings.max_time_s, DEPART_S + end))
    return run_case(cfg, ScenarioOverrides(mu=mu), out, settings)
