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
