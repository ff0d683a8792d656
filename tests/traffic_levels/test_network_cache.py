"""A process builds a generated road once: the network it writes again for the next case is
netconvert's own build of the same sources, byte for byte."""

from __future__ import annotations

import pytest

from eoam_sumo.traffic_levels import network
from eoam_sumo.traffic_levels.spec import TrafficSpec

pytestmark = pytest.mark.sumo


def test_a_reused_network_is_netconverts_build(tmp_path, monkeypatch):
    network._network_text.cache_clear()
    built = []
    real = network.build_network
    monkeypatch.setattr(network, "build_network", lambda nod: built.append(nod) or real(nod))
    curved = TrafficSpec("rural", "B", curve_radius_m=400.0, seed=7).checked()
    for name in ("first", "again"):
        (tmp_path / name).mkdir()
        network.write_network(curved, tmp_path / name)
    assert len(built) == 1  # the second came from the cache
    straight = TrafficSpec("rural", "B", seed=7).checked()
    (tmp_path / "other").mkdir()
    network.write_network(straight, tmp_path / "other")
    assert len(built) == 2  # other sources, another build
    network._network_text.cache_clear()
    (tmp_path / "fresh").mkdir()
    network.write_network(curved, tmp_path / "fresh")
    fresh = (tmp_path / "fresh" / "road.net.xml").read_bytes()
    assert (tmp_path / "again" / "road.net.xml").read_bytes() == fresh
    assert (tmp_path / "other" / "road.net.xml").read_bytes() != fresh
    network._network_text.cache_clear()
