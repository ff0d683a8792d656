"""A generated heavy-traffic scenario (the benchmark's traffic case): a straight two-way road,
three lanes each way, dense seeded random flows both ways, a car broken down in the ego's
lane from the start and the ego departing late behind it.

The road fills before the ego departs; the sumocfg asks for SUMO steps of ``step_length_s``
(the co-simulation runs the time before the ego's departure at that step). Same-direction
traffic keeps to the lanes left of the ego's (no lane changes), so that the ego's lane holds
only the broken-down car and the ego.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

ROAD_M = 3000.0  # road length [m]
SPEED_MPS = 20.0  # speed limit [m/s]
LANE_FLOW_VPH = 1800.0  # mean flow of each traffic lane [veh/h]
BROKEN_POS_M = 600.0  # the broken-down car's position on the ego's lane [m]
EGO_POS_M = 350.0  # the ego's departure position [m]


def write_traffic_scenario(
    folder: Path, *, ego_depart_s: float = 160.0, step_length_s: float = 0.5, seed: int = 42
) -> Path:
    """Write the network (netconvert), routes and ``traffic.sumocfg`` into ``folder``; the
    sumocfg's path. ``ego_depart_s`` whole multiples of ``step_length_s`` keep the handover
    at the departure."""
    folder.mkdir(parents=True, exist_ok=True)
    _write_network(folder)
    (folder / "t.rou.xml").write_text(_routes_text(ego_depart_s))
    cfg = folder / "traffic.sumocfg"
    cfg.write_text(
        '<configuration><input><net-file value="t.net.xml"/>'
        '<route-files value="t.rou.xml"/></input>'
        f'<time><begin value="0"/><step-length value="{step_length_s:g}"/></time>'
        f'<random_number><seed value="{seed}"/></random_number></configuration>'
    )
    return cfg


def _write_network(folder: Path) -> None:
    """``t.net.xml``: the straight road, three lanes each way, built by netconvert from the
    node and edge files written beside it."""
    import sumolib

    (folder / "t.nod.xml").write_text(
        f'<nodes><node id="a" x="0" y="0"/><node id="b" x="{ROAD_M:g}" y="0"/></nodes>'
    )
    (folder / "t.edg.xml").write_text(
        "<edges>"
        f'<edge id="fwd" from="a" to="b" numLanes="3" speed="{SPEED_MPS:g}"/>'
        f'<edge id="back" from="b" to="a" numLanes="3" speed="{SPEED_MPS:g}"/>'
        "</edges>"
    )
    subprocess.run(
        [
            sumolib.checkBinary("netconvert"),
            "-n",
            str(folder / "t.nod.xml"),
            "-e",
            str(folder / "t.edg.xml"),
            "--no-turnarounds",
            "true",
            "-o",
            str(folder / "t.net.xml"),
        ],
        check=True,
        capture_output=True,
    )


def _routes_text(ego_depart_s: float) -> str:
    """The route file: the broken-down car, the random flows (same-direction ones kept out of
    the ego's lane) until 600 s after the ego's departure, and the ego."""
    prob = LANE_FLOW_VPH / 3600.0  # departures per second of a lane
    flows = "".join(
        f'<flow id="{edge}{lane}" type="{vtype}" route="{edge}" begin="0"'
        f' end="{ego_depart_s + 600:g}" probability="{prob:g}" departLane="{lane}"'
        ' departSpeed="max"/>'
        for edge, lanes, vtype in (("fwd", (1, 2), "keep"), ("back", (0, 1, 2), "car"))
        for lane in lanes
    )
    return (
        "<routes>"
        '<vType id="car" length="4.6" width="1.8" decel="7.5" sigma="0.5"/>'
        '<vType id="keep" length="4.6" width="1.8" decel="7.5" sigma="0.5"'
        ' lcStrategic="-1" lcKeepRight="0" lcSpeedGain="0" lcCooperative="-1"/>'
        '<vType id="ego" length="4.6" width="1.8" decel="9"/>'
        '<route id="fwd" edges="fwd"/><route id="back" edges="back"/>'
        f'<vehicle id="broken" type="car" route="fwd" depart="0" departLane="0"'
        f' departPos="{BROKEN_POS_M:g}" departSpeed="0">'
        f'<stop lane="fwd_0" endPos="{BROKEN_POS_M:g}" duration="100000"/></vehicle>'
        f"{flows}"
        f'<vehicle id="ego" type="ego" route="fwd" depart="{ego_depart_s:g}" departLane="0"'
        f' departPos="{EGO_POS_M:g}" departSpeed="{SPEED_MPS:g}"/>'
        "</routes>"
    )
