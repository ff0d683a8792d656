"""The EOAM plans on the lowest friction of the lanes its manoeuvre uses (the net's lane
``friction``), real SUMO runs: the ego's lane mu 0.9, the lane it would change into 0.3."""

from __future__ import annotations

import pytest

from tests.sim.test_motorway_runs import motorway, run

pytestmark = pytest.mark.sumo

EDGES = (
    '<edges><edge id="mw" from="a" to="b" numLanes="2" speed="36.12" width="3.5">'
    '<lane index="0" friction="{ego}"/><lane index="1" friction="{left}"/></edge></edges>'
)


@pytest.mark.parametrize(("ego_mu", "left_mu"), [(0.9, 0.3), (0.9, 0.9)])
def test_the_plan_uses_the_lowest_friction_of_the_lanes_it_uses(tmp_path, ego_mu, left_mu):
    folder = tmp_path / "road"
    cfg = motorway(folder, ego_lane=0, edges=EDGES.format(ego=ego_mu, left=left_mu))
    summary, _ = run(cfg, tmp_path / "paper", "paper")
    assert summary["mu_believed_at_trigger"] == pytest.approx(min(ego_mu, left_mu))
    assert not summary["left_road"], summary["reason"]


EDGES3 = (
    '<edges><edge id="mw" from="a" to="b" numLanes="3" speed="36.12" width="3.5">'
    '<lane index="0" friction="{right}"/><lane index="1" friction="{ego}"/>'
    '<lane index="2" friction="{left}"/></edge></edges>'
)


def test_ice_on_the_lane_not_taken_does_not_lower_the_plan(tmp_path):
    """The ego in the middle lane, the right one icy (0.1), the left dry: the EOAM changes to
    the left and plans on the dry road (it took the lowest of both sides, 0.1, before)."""
    folder = tmp_path / "road"
    cfg = motorway(folder, ego_lane=1, edges=EDGES3.format(right=0.1, ego=0.9, left=0.9))
    summary, ts = run(cfg, tmp_path / "paper", "paper")
    assert summary["mu_believed_at_trigger"] == pytest.approx(0.9)
    assert ts["lateral_offset_m"].max() > 2.5, summary["reason"]  # into the left lane
