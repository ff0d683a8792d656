"""DMM sector rules (paper sec. 5-6, Figure 14) on hand-made boundaries."""

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from eoam_sumo.decision import SECTOR_ORDER, Action, BoundaryCurve, Sector, classify, dmm_sector

# S, Sb, B0, Bb, ttc at some closing speed: steering needs less than braking (high speed)
HIGH = dict(clear_m=30.0, clear_buffered_m=38.0, stop_m=60.0, stop_buffered_m=70.0, ttc_s=2.5)
# braking needs less than steering (low speed)
LOW = dict(clear_m=20.0, clear_buffered_m=25.0, stop_m=8.0, stop_buffered_m=12.0, ttc_s=2.5)


@pytest.mark.parametrize(
    ("bounds", "range_m", "speed", "sector"),
    [
        (HIGH, 29.0, 35.0, Sector.A),  # d <= S, d <= B0
        (LOW, 15.0, 10.0, Sector.C),  # d <= S, d > B0
        (HIGH, 35.0, 35.0, Sector.F),  # S < d <= Sb, d <= Bb
        (LOW, 22.0, 10.0, Sector.B),  # S < d <= Sb, d > Bb
        (HIGH, 50.0, 35.0, Sector.D),  # d > Sb, d <= Bb
        (HIGH, 80.0, 35.0, Sector.E),  # d > Sb, Bb; d <= 2.5 * 35
        (HIGH, 90.0, 35.0, Sector.G),  # beyond the TTC line
        (LOW, 24.9, 10.0, Sector.B),
        (LOW, 25.1, 10.0, Sector.G),  # d > Sb, Bb and beyond 2.5 s * 10 m/s = 25 m
    ],
)
def test_each_sector_region(bounds, range_m, speed, sector):
    assert classify(range_m, speed, **bounds) is sector


def test_fcw_band_and_boundaries_inclusive():
    b = dict(LOW, ttc_s=5.0)
    assert classify(25.1, 10.0, **b) is Sector.E  # 25.1 <= 50
    assert classify(50.0, 10.0, **b) is Sector.E  # on the TTC line
    assert classify(50.01, 10.0, **b) is Sector.G
    assert classify(30.0, 35.0, **HIGH) is Sector.A  # on S: still A
    assert classify(38.0, 35.0, **HIGH) is Sector.F  # on Sb: still F


def test_actions_and_warning():
    assert Sector.A.action is Action.LIMIT_BRAKE
    assert Sector.C.action is Action.BRAKE and Sector.D.action is Action.BRAKE
    assert Sector.B.action is Action.STEER and Sector.F.action is Action.STEER
    assert Sector.E.action is Action.FCW and Sector.G.action is Action.NONE
    assert [s.warns for s in SECTOR_ORDER] == [True] * 6 + [False]


@pytest.mark.parametrize("speed", [0.0, -3.0, math.nan, math.inf])
def test_not_closing_or_invalid_is_g(speed):
    assert classify(1.0, speed, **HIGH) is Sector.G


def test_invalid_range_is_g():
    assert classify(math.nan, 20.0, **HIGH) is Sector.G


bounds_st = st.tuples(
    st.floats(0.0, 200.0), st.floats(0.0, 50.0), st.floats(0.0, 400.0), st.floats(0.0, 50.0),
    st.floats(0.5, 30.0),
)


@given(bounds_st, st.floats(0.1, 60.0), st.lists(st.floats(0.0, 600.0), min_size=2))
def test_urgency_never_increases_with_distance(b, speed, ranges):
    s, ds, b0, db, ttc = b
    order = [
        SECTOR_ORDER.index(classify(r, speed, s, s + ds, b0, b0 + db, ttc))
        for r in sorted(ranges)
    ]
    assert order == sorted(order)


class AnalyticBoundaries:
    """Boundaries of the form the tables approximate: linear clearing, quadratic stopping."""

    class B:
        def __init__(self, v):
            self.clear_opt_m = 0.55 * v + 3.0
            self.clear_buffered_m = self.clear_opt_m + 0.3 * v + 2.0
            self.stop_m = v * v / 16.0
            self.stop_buffered_m = self.stop_m + 0.3 * v + 2.0
            self.ttc_s = 2.5

    def at(self, mu, v):
        assert 0.0 <= v <= 175 / 3.6 + 1e-9, "queried outside the speed range"
        return self.B(v)


@pytest.mark.parametrize("v", [0.0, 0.3, 1.0, 3.0, 5.5, 10.0, 33.3, 48.6, 60.0])
def test_boundary_curve_reproduces_the_boundaries(v):
    curve = BoundaryCurve(AnalyticBoundaries(), 1.0, 175 / 3.6)
    truth = AnalyticBoundaries.B(min(v, 175 / 3.6))
    expected = (truth.clear_opt_m, truth.clear_buffered_m, truth.stop_m, truth.stop_buffered_m,
                2.5)
    # linear between 0.25 m/s samples: exact for the linear ones, v^2 within 0.25^2 / 64
    assert curve.at(v) == pytest.approx(expected, abs=1e-3)


def test_boundary_curve_sector_agrees_with_classify():
    curve = BoundaryCurve(AnalyticBoundaries(), 1.0, 175 / 3.6)
    for v in (0.25, 2.0, 12.0, 30.0, 45.0):  # on the sample grid: the same numbers
        b = AnalyticBoundaries.B(v)
        for d in (1.0, 5.0, 8.0, 10.0, 25.0, 40.0, 70.0, 120.0):
            assert curve.sector(d, v) is dmm_sector(b, d, v)
    assert curve.sector(5.0, 0.0) is Sector.G
    assert curve.sector(5.0, math.nan) is Sector.G
