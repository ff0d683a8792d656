"""The level-of-service bands and the traffic aimed at them (no SUMO)."""

from __future__ import annotations

import pytest

from eoam_sumo.errors import InputError
from eoam_sumo.offline.tables import LookupTables
from eoam_sumo.traffic_levels import hcm
from eoam_sumo.traffic_levels.network import centre_line
from eoam_sumo.traffic_levels.spec import TrafficSpec


def test_freeway_bands_are_the_hcm_densities():
    # HCM 6th ed., Exhibit 12-15: A <= 11, B <= 18, C <= 26, D <= 35, E <= 45 pc/mi/ln
    assert [hcm.band(hcm.FREEWAY_DENSITY_PCMILN, lv) for lv in "ABCDE"] == [
        (0.0, 11.0),
        (11.0, 18.0),
        (18.0, 26.0),
        (26.0, 35.0),
        (35.0, 45.0),
    ]
    density_km, _ = hcm.freeway_target("C", 120.0)
    assert density_km * hcm.KM_PER_MI == pytest.approx(22.0)
    assert hcm.level_of("motorway", 22.0, 120.0) == "C"
    assert hcm.level_of("motorway", 46.0, 120.0) == "F"


def test_two_lane_targets_sit_mid_band_in_follower_density():
    for level in "ABCD":
        density_km, speed = hcm.two_lane_target(level, 100.0)
        flow_vph = density_km * speed * 3.6
        low, high = hcm.band(hcm.TWO_LANE_FD_HIGH, level)
        assert hcm.follower_density(flow_vph, speed) == pytest.approx(0.5 * (low + high))
    # below 50 mi/h the bands are wider (2.5, 5, 10, 15)
    assert hcm.two_lane_bounds(70.0) is hcm.TWO_LANE_FD_LOW
    assert hcm.two_lane_bounds(90.0) is hcm.TWO_LANE_FD_HIGH


def test_the_curve_has_its_radius():
    points = centre_line(300.0)
    # every point of the arc is 300 m from the circle's centre (2600, 300)
    arc = [p for p in points if p[0] >= 2600.0 and p[1] > 0.0][:-1]
    assert len(arc) > 10
    for x, y in arc:
        assert ((x - 2600.0) ** 2 + (y - 300.0) ** 2) ** 0.5 == pytest.approx(300.0, abs=1e-6)


@pytest.mark.parametrize(
    "spec, message",
    [
        (TrafficSpec("city", "A"), "road 'city'"),
        (TrafficSpec("rural", "F"), "level of service 'F'"),
        (TrafficSpec("rural", "A", lanes=2), "one lane each way"),
        (TrafficSpec("motorway", "A", lanes=1), "2 to 6 lanes"),
        (TrafficSpec("motorway", "A", curve_radius_m=400.0), "rural road only"),
        (TrafficSpec("rural", "A", curve_radius_m=50.0), "must be >= 150"),
        (TrafficSpec("rural", "A", speed_limit_kmh=500.0), "outside [30, 175]"),
    ],
)
def test_bad_specs_are_named(spec, message):
    with pytest.raises(InputError, match=message.replace("[", r"\[")):
        spec.checked()


def test_speed_limit_stops_where_the_tables_do():
    """A generated road's speed limit is the ego's entry speed: the generator accepts up to
    the default tables' top speed, what ``run`` accepts, and refuses one above it."""
    top_kmh = LookupTables.cached().speed_grid_mps[-1] * 3.6
    assert TrafficSpec("rural", "A", speed_limit_kmh=top_kmh).checked().speed_limit_kmh == top_kmh
    with pytest.raises(InputError, match=rf"speed limit 200 km/h is outside \[30, {top_kmh:g}\]"):
        TrafficSpec("rural", "A", speed_limit_kmh=200.0).checked()
