"""Road surface and markings read from a network file (the shipped highway and a hand-written
three-lane edge with a pavement)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from eoam_sumo.errors import InputError
from eoam_sumo.plotting.roadmap import read_road_map

HIGHWAY = Path(__file__).resolve().parents[2] / "networks" / "highway.net.xml"


def test_highway_lanes_and_markings():
    road = read_road_map(HIGHWAY, (0.0, -10.0, 200.0, 10.0))
    assert len(road.road) == 2 and not road.pavement and not road.dashed
    ys = sorted(float(np.mean(line[:, 1])) for line in road.solid)
    assert ys == pytest.approx([-3.5, 0.0, 0.0, 3.5])  # edges and the centre line (twice)
    for poly in road.road:  # each lane is 3.5 m wide
        assert np.ptp(poly[:, 1]) == pytest.approx(3.5)


def test_lanes_outside_the_box_are_left_out():
    road = read_road_map(HIGHWAY, (0.0, 500.0, 200.0, 600.0))
    assert not road.road and not road.solid


def test_dashed_lines_between_lanes_and_a_pavement(tmp_path):
    net = tmp_path / "three.net.xml"
    net.write_text(
        '<net><edge id="A" from="a" to="b">'
        '<lane id="A_0" index="0" width="2.0" allow="pedestrian" shape="0,-7 100,-7"/>'
        '<lane id="A_1" index="1" width="3.0" shape="0,-4.5 100,-4.5"/>'
        '<lane id="A_2" index="2" width="3.0" shape="0,-1.5 100,-1.5"/>'
        "</edge></net>"
    )
    road = read_road_map(net, (0.0, -10.0, 100.0, 0.0))
    assert len(road.pavement) == 1 and len(road.road) == 2
    # index 0 is the rightmost lane: the pavement, then the road's right edge, the dashed line
    # between the two driving lanes and the road's left edge
    assert [float(line[0, 1]) for line in road.solid] == pytest.approx([-6.0, 0.0])
    assert [float(line[0, 1]) for line in road.dashed] == pytest.approx([-3.0])


def test_a_broken_network_is_named(tmp_path):
    bad = tmp_path / "bad.net.xml"
    bad.write_text("<net><edge")
    with pytest.raises(InputError, match=r"bad\.net\.xml: cannot be read as a SUMO network"):
        read_road_map(bad, (0.0, 0.0, 1.0, 1.0))
