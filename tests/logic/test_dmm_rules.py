"""DMM sector rules (paper sec. 5-6, Figure 14) on hand-made boundaries."""

import math
from types import SimpleNamespace

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from eoam_sumo.decision import SECTOR_ORDER, Action, BoundaryCurve, Sector, classify, dmm_sector
from eoam_sumo.decision.dmm import FCW_LEAD_S

# S, Sb, B0, Bb, ttc at some closing speed: steering needs less than braking (high speed)
HIGH = {
    "clear_m": 30.0,
    "clear_buffered_m": 38.0,
    "stop_m": 60.0,
    "stop_buffered_m": 70.0,
    "ttc_s": 2.5,
}
# steering needs less than braking, but its buffer more than braking's (a B sector)
MID = {
    "clear_m": 30.0,
    "clear_buffered_m": 50.0,
    "stop_m": 35.0,
    "stop_buffered_m": 45.0,
    "ttc_s": 2.5,
}
# braking needs less than steering (low speed)
LOW = {
    "clear_m": 20.0,
    "clear_buffered_m": 25.0,
    "stop_m": 8.0,
    "stop_buffered_m": 12.0,
    "ttc_s": 2.5,
}


@pytest.mark.parametrize(
    ("bounds", "range_m", "speed", "sector"),
    [
        (HIGH, 29.0, 35.0, Sector.A),  # d <= S, d <= B0
        (LOW, 15.0, 10.0, Sector.C),  # d <= S, d > B0
        (HIGH, 35.0, 35.0, Sector.F),  # S < d <= Sb, d <= Bb
        (MID, 48.0, 20.0, Sector.B),  # S < d <= Sb, d > Bb
        (MID, 40.0, 20.0, Sector.F),  # S < d <= Sb, d <= Bb
        (MID, 29.0, 20.0, Sector.A),  # d <= S, d <= B0
        (LOW, 22.0, 10.0, Sector.C),  # S < d <= Sb, but B0 <= S: braking stops first
        (HIGH, 50.0, 35.0, Sector.D),  # d > Sb, d <= Bb
        (HIGH, 80.0, 35.0, Sector.E),  # d > Sb, Bb; d <= 2.5 * 35
        (HIGH, 90.0, 35.0, Sector.G),  # beyond the TTC line
        (LOW, 24.9, 10.0, Sector.C),
        (LOW, 25.1, 10.0, Sector.G),  # d > Sb, Bb and beyond 2.5 s * 10 m/s = 25 m
    ],
)
def test_each_sector_region(bounds, range_m, speed, sector):
    """The paper's rules (Figure 14), and braking where stopping is shorter than clearing
    (B0 <= S, which the paper leaves open); the warning line is T alone."""
    assert classify(range_m, speed, **bounds, warn_lead_s=0.0) is sector


@pytest.mark.parametrize(
    ("bounds", "speed", "last_e_m"),
    [
        (HIGH, 35.0, 70.0 + FCW_LEAD_S * 35.0),  # Bb + 0.85 s v = 99.75 m beyond T = 87.5 m
        (LOW, 10.0, 25.0 + FCW_LEAD_S * 10.0),  # Sb + 0.85 s v = 33.5 m beyond T = 25 m
        (dict(LOW, ttc_s=5.0), 10.0, 50.0),  # T = 50 m already leads Sb by 2.5 s
    ],
)
def test_the_warning_leads_the_braking_or_steering_by_fcw_lead_s(bounds, speed, last_e_m):
    """W = max(T, max(Sb, Bb) + FCW_LEAD_S v): at a steady closing speed the FCW comes at
    least 0.8 s before sector D, B or F (UN R152 para. 5.2.1.1), with a margin."""
    assert FCW_LEAD_S >= 0.8
    assert classify(last_e_m, speed, **bounds) is Sector.E
    assert classify(last_e_m + 0.01, speed, **bounds) is Sector.G
    edge = max(bounds["clear_buffered_m"], bounds["stop_buffered_m"])
    assert (last_e_m - edge) / speed >= FCW_LEAD_S - 1e-12


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
    st.floats(0.0, 200.0),
    st.floats(0.0, 50.0),
    st.floats(0.0, 400.0),
    st.floats(0.0, 50.0),
    st.floats(0.5, 30.0),
)


@settings(database=None)
@given(bounds_st, st.floats(0.1, 60.0), st.lists(st.floats(0.0, 600.0), min_size=2))
def test_urgency_never_increases_with_distance(b, speed, ranges):
    s, ds, b0, db, ttc = b
    order = [
        SECTOR_ORDER.index(classify(r, speed, s, s + ds, b0, b0 + db, ttc)) for r in sorted(ranges)
    ]
    assert order == sorted(order)


class AnalyticBoundaries:
    """Boundaries piecewise linear in v between the grid speeds (as the tables' ``at``)."""

    speed_grid_mps = tuple(v / 3.6 for v in range(20, 180, 5))

    @staticmethod
    def exact(v):
        return (0.55 * v + 3.0, 0.85 * v + 5.0, v * v / 16.0, v * v / 16.0 + 0.3 * v + 2.0, 2.5)

    def at(self, mu, v):
        grid = self.speed_grid_mps
        if v <= grid[0]:  # scaled to 0 below the grid
            row = [x * max(v, 0.0) / grid[0] for x in self.exact(grid[0])]
            row[4] = 2.5
        elif v >= grid[-1]:
            row = self.exact(grid[-1])
        else:
            j = next(i for i, g in enumerate(grid) if g > v)
            w = (v - grid[j - 1]) / (grid[j] - grid[j - 1])
            a, b = self.exact(grid[j - 1]), self.exact(grid[j])
            row = [x + w * (y - x) for x, y in zip(a, b, strict=True)]
        names = ("clear_opt_m", "clear_buffered_m", "stop_m", "stop_buffered_m", "ttc_s")
        return SimpleNamespace(**dict(zip(names, row, strict=True)))


@pytest.mark.parametrize("v", [0.0, 0.3, 1.0, 3.0, 5.5, 5.6, 10.0, 33.3, 48.6, 60.0])
def test_boundary_curve_reproduces_the_boundaries(v):
    fake = AnalyticBoundaries()
    curve = BoundaryCurve(fake, 1.0, fake.speed_grid_mps)
    b = fake.at(1.0, v)
    expected = (b.clear_opt_m, b.clear_buffered_m, b.stop_m, b.stop_buffered_m, b.ttc_s)
    assert curve.at(v) == pytest.approx(expected, rel=1e-12, abs=1e-12)


def test_boundary_curve_sector_agrees_with_dmm_sector():
    fake = AnalyticBoundaries()
    curve = BoundaryCurve(fake, 1.0, fake.speed_grid_mps)
    for v in (0.25, 2.0, 7.7, 12.0, 30.0, 45.0):
        for d in (1.0, 5.0, 8.0, 10.0, 25.0, 40.0, 70.0, 120.0):
            assert curve.sector(d, v) is dmm_sector(fake.at(1.0, v), d, v)
    for bad in (0.0, -1.0, math.nan, math.inf, 1e308 * 10):
        assert curve.sector(5.0, bad) is Sector.G
    assert curve.at(1e300) == curve.at(60.0)
