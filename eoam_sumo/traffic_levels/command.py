"""``eoam-sumo scenario ROAD --los L ... --out DIR``: write a generated traffic scenario."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from eoam_sumo.outputs.staging import OutputKind, output_folder
from eoam_sumo.seeds import seed_argument
from eoam_sumo.traffic_levels.hcm import LEVELS
from eoam_sumo.traffic_levels.network import NAME
from eoam_sumo.traffic_levels.spec import ROADS, TrafficSpec

SCENARIO_CFG = "scenario.sumocfg"
SCENARIO_JSON = "scenario.json"
#: What shows a folder holds a generated scenario (``build.write_scenario``'s files).
SCENARIO_OUTPUT = OutputKind(
    "scenario",
    (
        SCENARIO_CFG,
        SCENARIO_JSON,
        "scenario.rou.xml",
        f"{NAME}.nod.xml",
        f"{NAME}.edg.xml",
        f"{NAME}.net.xml",
    ),
)


def add_scenario_arguments(sub) -> None:
    """The ``scenario`` sub-command's arguments."""
    p = sub.add_parser(
        "scenario",
        help="write a road with traffic at a level of service, an obstacle and the ego",
        description="Write DIR/scenario.sumocfg and its files: a rural two-lane road or a "
        "motorway, traffic at a Highway Capacity Manual level of service settled by a "
        "warm-up run, the ego placed in a gap of it behind an obstacle that brakes to a stop.",
    )
    p.add_argument("road", choices=ROADS, help="rural (two lanes, two-way) or motorway")
    p.add_argument("--los", required=True, choices=LEVELS, help="level of service A-E")
    p.add_argument("--lanes", type=int, help="motorway: lanes of the carriageway (3)")
    p.add_argument("--speed-limit-kmh", type=float, help="speed limit (rural 100, motorway 120)")
    p.add_argument("--curve-radius-m", type=float, help="rural: a left-hand curve of this radius")
    p.add_argument("--seed", type=seed_argument, default=0, help="seed of the traffic (0)")
    p.add_argument("--out", type=Path, default=Path("out/scenario"), help="output folder")


def cmd_scenario(args: argparse.Namespace) -> int:
    """Write the scenario; one line with its level as measured. The folder is written by
    this process alone; over an earlier scenario the new one is written into a staging folder
    that replaces it once complete (:mod:`eoam_sumo.outputs.staging`), so an interrupted run
    never leaves a new network beside old routes."""
    spec = TrafficSpec(
        args.road, args.los, args.lanes, args.speed_limit_kmh, args.curve_radius_m, args.seed
    ).checked()
    from eoam_sumo.traffic_levels.build import write_scenario

    with output_folder(args.out, SCENARIO_OUTPUT) as out:
        write_scenario(spec, out)
        record = json.loads((out / SCENARIO_JSON).read_text(encoding="utf-8"))
    measured = record["measured"]
    print(
        f"{spec.road} LoS {spec.los}: measured {measured['measure']} = {measured['value']:g} "
        f"(level {measured['level']}) -> {args.out / SCENARIO_CFG}"
    )
    if measured["level"] != spec.los:
        print(
            f"eoam-sumo: the traffic settled at level {measured['level']}, not {spec.los}, "
            f"after {measured['attempts']} warm-ups; another --seed may reach {spec.los} "
            "(scenario.json records the level measured)",
            file=sys.stderr,
        )
    return 0
