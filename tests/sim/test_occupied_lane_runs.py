"""No lane change into an occupied lane under any policy, real SUMO runs
on the motorway of ``test_motorway_runs`` with the ego in its right lane (the only lane to
change into is the middle one): a car alongside, and a faster one coming up from behind,
close it to the paper's policy too; the EOAM brakes in lane instead."""

from __future__ import annotations

import pytest

from eoam_sumo import netbuild
from tests.sim.test_motorway_runs import SPEED_MPS, car, motorway, run

pytestmark = pytest.mark.sumo

EGO_LENGTH_M = 4.92
TAKEN = {
    # its front level with the ego's front, as fast
    "alongside": car("left", 1, 100.0, SPEED_MPS),
    # 11 m behind the ego's rear at 40 m/s: it would have to brake hard behind the ego
    "coming up": car("left", 1, 100.0 - EGO_LENGTH_M - 11.0, 40.0),
}


@pytest.mark.parametrize("taken", sorted(TAKEN))
@pytest.mark.parametrize("policy", ["paper", "safe"])
def test_a_taken_middle_lane_is_never_entered(tmp_path, policy, taken):
    cfg = motorway(tmp_path / "road", ego_lane=0, others=TAKEN[taken])
    summary, ts = run(cfg, tmp_path / policy, policy)
    assert ts["lateral_offset_m"].max() < 1.0  # never into the middle lane
    assert summary["collision_with"] in ("none", "aro"), summary["reason"]
    assert 2 not in summary["modes_visited"]
    assert "in the target lane" in summary["reason"] or summary["collision_with"] == "aro"


def test_with_the_middle_lane_free_the_paper_policy_still_passes(tmp_path):
    cfg = motorway(tmp_path / "road", ego_lane=0)
    summary, ts = run(cfg, tmp_path / "paper", "paper")
    assert 2 in summary["modes_visited"]
    assert summary["collision_with"] == "none", summary["reason"]
    assert ts["lateral_offset_m"].max() > 2.5


def test_the_gap_to_the_obstacle_is_never_a_followers(tmp_path):
    # a car 0.8 m behind the ego's rear in its lane, as fast: the ego passes the ARO in the
    # free middle lane; the least gap to the obstacle is the same with and without it
    follower = car("behind", 0, 100.0 - EGO_LENGTH_M - 0.8, SPEED_MPS)
    alone, _ = run(motorway(tmp_path / "alone", ego_lane=0), tmp_path / "a", "paper")
    followed, _ = run(
        motorway(tmp_path / "followed", ego_lane=0, others=follower), tmp_path / "f", "paper"
    )
    assert alone["collision_with"] == "none" and followed["collision_with"] == "none"
    assert followed["min_gap_aro_m"] == pytest.approx(alone["min_gap_aro_m"], abs=0.05)


def test_a_right_lane_closed_to_cars_ahead_is_never_evaded_into(tmp_path):
    # the right lane is open where the ego starts, closed to cars from 100 m ahead on (the
    # lane permissions along the manoeuvre, not at its start only); the left lane is taken
    folder = tmp_path / "road"
    cfg = motorway(folder, ego_lane=1, others=TAKEN["alongside"].replace('"1"', '"2"'))
    (folder / "m.nod.xml").write_text(
        '<nodes><node id="a" x="0" y="0"/><node id="b" x="200" y="0"/>'
        '<node id="c" x="3000" y="0"/></nodes>'
    )
    (folder / "m.edg.xml").write_text(
        '<edges><edge id="mw" from="a" to="b" numLanes="3" speed="36.12" width="3.5"/>'
        '<edge id="mw2" from="b" to="c" numLanes="3" speed="36.12" width="3.5">'
        '<lane index="0" disallow="passenger"/></edge></edges>'
    )
    netbuild.build_network(folder / "m.nod.xml")
    routes = (folder / "r.rou.xml").read_text().replace('edges="mw"', 'edges="mw mw2"')
    (folder / "r.rou.xml").write_text(routes)
    for policy in ("paper", "safe"):
        summary, ts = run(cfg, tmp_path / policy, policy)
        assert ts["lateral_offset_m"].min() > -1.0, policy  # never into the closed lane
        assert ts["lateral_offset_m"].max() < 1.0, policy  # nor into the taken one
        assert summary["collision_with"] in ("none", "aro"), summary["reason"]
