"""The protocols' network: the targets' rails under the ego lane are closed to the ego.

SUMO places the ego each step by ``moveToXY``, which measures its distance to every lane the
ego may use within 100 m; the rails (one per offset and lane-change path, 4 km long) would
make that most of a protocol run's SUMO time, so they disallow the ego's class.
"""

from __future__ import annotations

import pytest
import sumolib

from eoam_sumo.protocols.points import protocol_points
from eoam_sumo.protocols.scenario import EGO_VCLASS, write_scenarios

pytestmark = pytest.mark.sumo


def test_only_the_road_lets_the_ego_on_and_every_target_drives_its_rail(tmp_path):
    points = protocol_points("euroncap-aeb-c2c-2026", 1.85)
    write_scenarios(points, tmp_path)
    net = sumolib.net.readNet(str(tmp_path / "protocol.net.xml"))
    road = {"E0", "-E0"}
    for edge in net.getEdges():
        assert edge.allows(EGO_VCLASS) == (edge.getID() in road), edge.getID()
        assert edge.allows("passenger"), edge.getID()
    vtypes = list(sumolib.xml.parse(str(tmp_path / "protocol_vtypes.add.xml"), "vType"))
    assert {t.id: t.vClass for t in vtypes}["ego"] == EGO_VCLASS
    assert {t.vClass for t in vtypes if t.id != "ego"} == {"passenger"}
    for point in points[:: max(len(points) // 12, 1)]:
        routes = tmp_path / f"{point.point_id}.rou.xml"
        edges = {r.id: r.edges for r in sumolib.xml.parse(str(routes), "route")}
        assert edges["ego_route"] == "E0"
        assert edges["target_route"] not in road  # the target on its rail, the ego never
