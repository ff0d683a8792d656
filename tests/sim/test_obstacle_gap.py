"""The obstacle keeps its identity once it leaves the ego's lane band: ``min_gap_aro_m`` is the
closest approach to it, not the closest while its centre was in the band."""

from __future__ import annotations

import json

import pandas as pd
import pytest

from eoam_sumo.cli import main
from eoam_sumo.world.geometry import OrientedBox, box_distance
from tests.builders import netconvert, write_sumocfg

pytestmark = pytest.mark.sumo

NODES = (
    '<nodes><node id="a" x="0" y="0"/><node id="j" x="600" y="0" type="priority"/>'
    '<node id="b" x="3000" y="0"/><node id="n" x="600" y="300"/>'
    '<node id="s" x="600" y="-300"/></nodes>'
)
EDGES = (
    "<edges>"
    + "".join(
        f'<edge id="{e}" from="{f}" to="{t}" numLanes="1" speed="{v}" width="3.5" priority="{p}"/>'
        for e, f, t, v, p in (
            ("E", "a", "j", 30, 5),
            ("-E", "j", "a", 30, 5),
            ("E2", "j", "b", 30, 5),
            ("-E2", "b", "j", 30, 5),
            ("N", "n", "j", 15, 1),
            ("-S", "j", "s", 15, 1),
        )
    )
    + "</edges>"
)
ROUTES = """<routes>
<vType id="ego" vClass="passenger" length="4.92" width="1.85" sigma="0"/>
<vType id="ped" vClass="pedestrian" maxSpeed="1.3" jmIgnoreFoeProb="1"
 jmIgnoreFoeSpeed="100" speedDev="0" width="0.5" length="0.3"/>
<vehicle id="ego" type="ego" depart="1" departLane="0" departPos="100" departSpeed="27.78"
 insertionChecks="none"><route edges="E E2"/></vehicle>
<person id="p1" type="ped" depart="1" departPos="283">
 <walk edges="N -S" arrivalPos="100"/></person>
</routes>
"""


def test_a_person_crossing_on_out_of_the_lane_keeps_the_obstacle_gap(tmp_path):
    """A person crosses the ego's road at a junction: the obstacle while in the lane (the ego
    brakes), then walks on across and the ego passes it 2.6 m away: ``min_gap_aro_m`` is the
    closest box gap over the run (it was 14.66 m, measured while the person was in the band),
    computed here from traffic.csv's boxes."""
    netconvert(tmp_path, "junc", NODES, EDGES, "--no-turnarounds", "true")
    (tmp_path / "r.rou.xml").write_text(ROUTES)
    cfg = write_sumocfg(tmp_path / "s.sumocfg", "junc.net.xml", "r.rou.xml")
    out = tmp_path / "out"
    assert main(["run", str(cfg), "--speed-kmh", "100", "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    traffic = pd.read_csv(out / "traffic.csv")
    person = traffic[traffic["id"] == "p1"].set_index("time_s")
    ego = traffic[traffic["id"] == "ego"].set_index("time_s")
    assert (person["role"] == "aro").any()
    both = person.index.intersection(ego.index)
    gaps = [box_distance(_box(ego.loc[t]), _box(person.loc[t])) for t in both]
    assert min(gaps) > 1.0  # passed beside, not in the path
    assert summary["min_gap_aro_m"] == pytest.approx(min(gaps), abs=0.3)


def _box(row) -> OrientedBox:
    """A traffic.csv row's footprint (its pose is the box's centre)."""
    return OrientedBox(row["x_m"], row["y_m"], row["heading_rad"], row["length_m"], row["width_m"])
