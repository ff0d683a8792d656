"""The length scan of ``QuinticShift.for_lateral_accel`` skips the full check of a length whose
coarse-grid peak already misses the budget; the shift it returns is the very one (to the bit)
that the scan with the full check at every length returns."""

import math

from hypothesis import given, settings
from hypothesis import strategies as st

from eoam_sumo.manoeuvre import quintic_shift as q
from eoam_sumo.manoeuvre.quintic_shift import QuinticShift


def _full_scan(y0, slope0, y1, speed, accel, min_length, kappa0) -> QuinticShift:
    """The scan with the full check at every length (the method's own steps otherwise)."""
    limit = accel / max(speed * speed, 1e-9)
    rest = math.sqrt(10.0 * math.sqrt(3.0) / 3.0 * max(abs(y1 - y0), 1e-3) / limit)
    length = max(min_length, 0.3 * rest) if slope0 == 0.0 else min_length
    top = 4.0 * min_length + 8.0 * (rest + abs(slope0) * speed * speed / accel)
    state = (y0, slope0, y1, kappa0)
    failed, lengths = None, []
    while length <= top:
        traj = QuinticShift(y0, slope0, y1, length, kappa0)
        if traj._check(q._SEARCH_U)[1] <= q.OVERSHOOT_TOL_M and traj._margin(limit) <= 0.0:
            if failed is None:
                return traj
            return q._first_within(QuinticShift, state, limit, failed, length)
        failed = length
        lengths.append(length)
        length *= q.LENGTH_STEP
    return q._least_peak(QuinticShift, state, lengths, min_length)


@settings(max_examples=40, deadline=None)
@given(
    y0=st.floats(-4.0, 4.0),
    slope0=st.one_of(st.just(0.0), st.floats(-0.1, 0.1)),
    y1=st.floats(-4.0, 4.0),
    speed=st.floats(2.0, 46.0),
    accel=st.floats(0.5, 9.0),
    min_length=st.floats(1.0, 30.0),
    kappa0=st.one_of(st.just(0.0), st.floats(-0.01, 0.01)),
)
def test_scan_returns_the_full_checks_shift(y0, slope0, y1, speed, accel, min_length, kappa0):
    got = QuinticShift.for_lateral_accel(y0, slope0, y1, speed, accel, min_length, kappa0)
    want = _full_scan(y0, slope0, y1, speed, accel, min_length, kappa0)
    assert got.length_m == want.length_m
    assert got._c == want._c


def test_a_return_from_rest_at_motorway_speed():
    """The policy's return shift (3.5 m from rest at 30 m/s, 0.3 g): the same shift."""
    args = (3.5, 0.0, 0.0, 30.0, 2.943, 10.0, 0.0)
    assert QuinticShift.for_lateral_accel(*args)._c == _full_scan(*args)._c
