"""Road frame of a manoeuvre: station and lateral offset along the ego's original lane.

The EOAM geometry (paper sec. 4.2-4.3) is written in a frame attached to the lane the ego
starts in: ``s_m`` along its centre line, ``d_m`` the lateral offset (left positive, towards
the oncoming lane), and the road heading. The centre line is a polyline taken from the SUMO
network, so curved and user-made roads work as well as the paper's straight one.
"""

from __future__ import annotations

import math
from bisect import bisect_right
from collections.abc import Sequence
from itertools import pairwise


class RoadFrame:
    """Projection of points onto a polyline centre line (station, offset, heading, curvature)."""

    def __init__(self, points: Sequence[Sequence[float]]):
        pts = [(float(p[0]), float(p[1])) for p in points]
        # drop repeated points, which give zero-length segments
        clean = [pts[0]]
        for p in pts[1:]:
            if math.hypot(p[0] - clean[-1][0], p[1] - clean[-1][1]) > 1e-6:
                clean.append(p)
        if len(clean) < 2:
            raise ValueError("road centre line needs at least two distinct points")
        self._x = [p[0] for p in clean]
        self._y = [p[1] for p in clean]
        self._s = [0.0]
        self._hx, self._hy, self._len = [], [], []
        for i in range(len(clean) - 1):
            dx, dy = self._x[i + 1] - self._x[i], self._y[i + 1] - self._y[i]
            seg = math.hypot(dx, dy)
            self._hx.append(dx / seg)
            self._hy.append(dy / seg)
            self._len.append(seg)
            self._s.append(self._s[-1] + seg)
        # smooth heading: value at the thinned segments' midpoints and slope (the curvature)
        # to the next one; ``_mid_hint`` the interval of the last lookup
        self._mids, self._mid_yaw, self._mid_slope = _smooth_heading(clean, self._s)
        self._mid_hint = 0
        self._hint = 0

    @property
    def length_m(self) -> float:
        return self._s[-1]

    def project(self, x: float, y: float) -> tuple[float, float, float]:
        """(s_m, d_m, road_yaw_rad) of a point. Walks the polyline from the last answer: forward
        while the point lies past a segment's end, else backward while it lies before its start
        (beyond the ends, the first and last segments extend). The heading is the smooth road
        heading of ``_smooth_heading`` (continuous, not wrapped), not the segment's own: that
        jumps at every vertex (0.017 rad for 25 m chords of a 1500 m curve), which a look-ahead
        steering feedback 30 m ahead would turn into half-metre steps."""
        last = len(self._len) - 1
        i = self._hint
        hx, hy, xs, ys, seg = self._hx, self._hy, self._x, self._y, self._len
        rx, ry = x - xs[i], y - ys[i]
        along = rx * hx[i] + ry * hy[i]
        while along > seg[i] and i < last:
            i += 1
            rx, ry = x - xs[i], y - ys[i]
            along = rx * hx[i] + ry * hy[i]
        if i == self._hint:
            while along < 0.0 and i > 0:
                i -= 1
                rx, ry = x - xs[i], y - ys[i]
                along = rx * hx[i] + ry * hy[i]
        self._hint = i
        s_m = self._s[i] + along
        mids, j, top = self._mids, self._mid_hint, len(self._mids) - 1  # _mid_interval inlined
        while j < top and s_m >= mids[j + 1]:
            j += 1
        while j > 0 and s_m < mids[j]:
            j -= 1
        self._mid_hint = j
        h = s_m if s_m > 0.0 else 0.0  # beyond its ends the road runs straight on
        if h > self._s[-1]:
            h = self._s[-1]
        yaw = self._mid_yaw[j] + (h - mids[j]) * self._mid_slope[j]
        return s_m, ry * hx[i] - rx * hy[i], yaw

    def _mid_interval(self, s_m: float) -> int:
        """Index j of the midpoint interval [mids[j], mids[j + 1]) holding s (0 before the
        first, the last beyond it), walked from the last answer."""
        mids, j, last = self._mids, self._mid_hint, len(self._mids) - 1
        while j < last and s_m >= mids[j + 1]:
            j += 1
        while j > 0 and s_m < mids[j]:
            j -= 1
        self._mid_hint = j
        return j

    def point_at(self, s_m: float, d_m: float = 0.0) -> tuple[float, float, float]:
        """(x, y, road_yaw) of the point at station s and offset d (extrapolated at the ends)."""
        i = min(max(bisect_right(self._s, s_m) - 1, 0), len(self._len) - 1)
        along = s_m - self._s[i]
        hx, hy = self._hx[i], self._hy[i]
        return (
            self._x[i] + along * hx - d_m * hy,
            self._y[i] + along * hy + d_m * hx,
            math.atan2(hy, hx),
        )

    def curvature_at(self, s_m: float) -> float:
        """Signed curvature (1/m) at station s: the slope of the smooth heading (0 beyond the
        ends of the road)."""
        j = self._mid_interval(s_m)
        return self._mid_slope[j] if 0.0 <= s_m <= self._s[-1] else 0.0


HEADING_MIN_SEGMENT_M = 10.0
"""Heading and curvature are measured on the centre line with points closer than this to the
last kept one dropped. SUMO joins the lanes of consecutive edges by chords of a few
decimetres to a few metres across each junction, which turn sharply when the lane centre
shifts there (a width change moves it by a quarter of a metre in 3 m); over so short a length
that would spike the curvature, and the look-ahead 30 m ahead would turn the heading step into
metres of error. 10 m keeps the 25 m chords of netconvert's curves and arcs as they are."""


def _smooth_heading(points: list, stations: list) -> tuple[list, list, list]:
    """(midpoint stations, heading there, slope to the next midpoint) of the road's smooth
    heading: each segment of the polyline thinned to ``HEADING_MIN_SEGMENT_M`` gives its
    heading (unwrapped: continuous along the road) at its midpoint, interpolated linearly in
    between and extrapolated from the first and last midpoints to the road's ends; the slope
    is the curvature (the heading change at a vertex over the distance between the
    neighbouring midpoints; 0 on a straight line)."""
    kept, kept_s = [points[0]], [0.0]
    for p, s_m in zip(points[1:-1], stations[1:-1]):
        if s_m - kept_s[-1] >= HEADING_MIN_SEGMENT_M and stations[-1] - s_m >= \
                HEADING_MIN_SEGMENT_M:
            kept.append(p)
            kept_s.append(s_m)
    kept.append(points[-1])
    kept_s.append(stations[-1])
    mids, yaws = [], []
    for (p, q), (s0, s1) in zip(pairwise(kept), pairwise(kept_s)):
        yaw = math.atan2(q[1] - p[1], q[0] - p[0])
        if yaws:  # unwrapped: continuous along the road
            yaw = yaws[-1] + (yaw - yaws[-1] + math.pi) % (2.0 * math.pi) - math.pi
        mids.append(0.5 * (s0 + s1))
        yaws.append(yaw)
    slopes = [(y1 - y0) / (m1 - m0) for (y0, y1), (m0, m1) in zip(pairwise(yaws),
                                                                   pairwise(mids))]
    return mids, yaws, [*slopes, slopes[-1] if slopes else 0.0]
