"""Road frame of a manoeuvre: station and lateral offset along the ego's original lane.

The EOAM geometry (paper sec. 4.2-4.3) is written in a frame attached to the lane the ego
starts in: ``s_m`` along its centre line, ``d_m`` the lateral offset (left positive, towards
the oncoming lane), and the road heading. The centre line is a polyline taken from the SUMO
network, so curved and user-made roads work as well as the paper's straight one.

:class:`RoadFrame` answers the step loop's many projections in plain floats, walking from the
last answer; the numpy functions :func:`arclength`, :func:`point_at` and :func:`project`
answer one-off questions about a whole polyline (a SUMO lane shape, the ego's centre line).
"""

from __future__ import annotations

import math
from bisect import bisect_right
from collections.abc import Sequence
from itertools import pairwise

import numpy as np


class RoadFrame:
    """Projection of points onto a polyline centre line (station, offset, heading, curvature)."""

    def __init__(self, points: Sequence[Sequence[float]] | np.ndarray):
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
        # smooth heading: its values at break stations and the slopes (the curvature) to the
        # next break; ``_break_hint`` the interval of the last lookup
        self._breaks, self._break_yaw, self._break_slope = _smooth_heading(clean, self._s)
        self._break_hint = 0
        self._hint = 0
        self._last_segment = len(self._len) - 1
        self._last_break = len(self._breaks) - 1
        self._length = self._s[-1]

    @property
    def length_m(self) -> float:
        return self._s[-1]

    def locate(self, x: float, y: float) -> None:
        """Start the projections' walk at the segment nearest to (x, y), searched over the
        whole line: a road that curves back (a hairpin, a loop) passes a point of its return
        leg level with its first straight, where a walk from the start would stop."""
        best, best_i = math.inf, 0
        for i in range(len(self._len)):
            rx, ry = x - self._x[i], y - self._y[i]
            along = min(max(rx * self._hx[i] + ry * self._hy[i], 0.0), self._len[i])
            dist = math.hypot(rx - along * self._hx[i], ry - along * self._hy[i])
            if dist < best:
                best, best_i = dist, i
        self._hint = best_i

    def project(self, x: float, y: float) -> tuple[float, float, float]:
        """(s_m, d_m, road_yaw_rad) of a point. Walks the polyline from the last answer: forward
        while the point lies past a segment's end, else backward while it lies before its start
        (beyond the ends, the first and last segments extend). The heading is the smooth road
        heading of ``_smooth_heading`` (continuous, not wrapped), not the segment's own: that
        jumps at every vertex (0.017 rad for 25 m chords of a 1500 m curve), which a look-ahead
        steering feedback 30 m ahead would turn into half-metre steps."""
        last = self._last_segment
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
        # the smooth heading's interval (``_break_interval``, inlined: the hot path)
        breaks, j, j_last = self._breaks, self._break_hint, self._last_break
        while j < j_last and s_m >= breaks[j + 1]:
            j += 1
        while j > 0 and s_m < breaks[j]:
            j -= 1
        self._break_hint = j
        # beyond its ends the road runs straight on: s clamped to [0, length] (comparisons
        # here cost less than min and max calls; NaN gives 0, as max(0.0, s) does)
        if not s_m > 0.0:
            h = 0.0
        elif self._length < s_m:
            h = self._length
        else:
            h = s_m
        yaw = self._break_yaw[j] + (h - breaks[j]) * self._break_slope[j]
        return s_m, ry * hx[i] - rx * hy[i], yaw

    def _break_interval(self, s_m: float) -> int:
        """Index j of the interval [breaks[j], breaks[j + 1]) of the smooth heading holding s
        (0 before the first, the last beyond it), walked from the last answer."""
        breaks, j, last = self._breaks, self._break_hint, len(self._breaks) - 1
        while j < last and s_m >= breaks[j + 1]:
            j += 1
        while j > 0 and s_m < breaks[j]:
            j -= 1
        self._break_hint = j
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
        j = self._break_interval(s_m)
        return self._break_slope[j] if 0.0 <= s_m <= self._s[-1] else 0.0


HEADING_MIN_SEGMENT_M = 10.0
"""Heading and curvature are measured on the centre line with points closer than this to the
last kept one dropped. SUMO joins the lanes of consecutive edges by chords of a few
decimetres to a few metres across each junction, which turn sharply when the lane centre
shifts there (a width change moves it by a quarter of a metre in 3 m); over so short a length
that would spike the curvature, and the look-ahead 30 m ahead would turn the heading step into
metres of error. 10 m keeps the 25 m chords of netconvert's curves and arcs as they are."""


HEADING_BLEND_M = 12.5
"""At a vertex of the thinned centre line the heading turns from one segment's to the next's
linearly, from the middle of the segment before (at most this far back) to the middle of the
one after (at most this far on): chord midpoint to chord midpoint on curves drawn with chords
of up to 25 m, and straight road right up to the curve where a long straight edge meets one."""


def _smooth_heading(points: list, stations: list) -> tuple[list, list, list]:
    """(break stations, heading there, slope to the next break) of the road's smooth heading:
    on the polyline thinned to ``HEADING_MIN_SEGMENT_M``, each segment's own heading
    (unwrapped: continuous along the road), turning linearly to the next segment's around
    their vertex (``HEADING_BLEND_M``); held from the road's start and to its end. The slope
    is the curvature: the heading change over the turn's length at a vertex, 0 along each
    segment's straight part and on a straight road. Breaks start at 0 and end at the road's
    length."""
    kept, kept_s = [points[0]], [0.0]
    for p, s_m in zip(points[1:-1], stations[1:-1]):
        if (
            s_m - kept_s[-1] >= HEADING_MIN_SEGMENT_M
            and stations[-1] - s_m >= HEADING_MIN_SEGMENT_M
        ):
            kept.append(p)
            kept_s.append(s_m)
    kept.append(points[-1])
    kept_s.append(stations[-1])
    yaws: list[float] = []
    for p, q in pairwise(kept):
        yaw = math.atan2(q[1] - p[1], q[0] - p[0])
        if yaws:  # unwrapped: continuous along the road
            yaw = yaws[-1] + (yaw - yaws[-1] + math.pi) % (2.0 * math.pi) - math.pi
        yaws.append(yaw)
    breaks, values = [0.0], [yaws[0]]
    for k in range(1, len(yaws)):  # the vertex between segments k - 1 and k
        v = kept_s[k]
        before = min(HEADING_BLEND_M, 0.5 * (v - kept_s[k - 1]))
        after = min(HEADING_BLEND_M, 0.5 * (kept_s[k + 1] - v))
        if v - before > breaks[-1]:
            breaks.append(v - before)
            values.append(yaws[k - 1])
        breaks.append(v + after)
        values.append(yaws[k])
    if stations[-1] > breaks[-1]:
        breaks.append(stations[-1])
        values.append(yaws[-1])
    slopes = [
        (y1 - y0) / (b1 - b0) for (y0, y1), (b0, b1) in zip(pairwise(values), pairwise(breaks))
    ]
    return breaks, values, [*slopes, 0.0]


def arclength(poly: np.ndarray) -> np.ndarray:
    """Arc length at each vertex of an (N, 2) polyline, from 0."""
    return np.concatenate(([0.0], np.cumsum(np.hypot(*np.diff(poly, axis=0).T))))


def point_at(poly: np.ndarray, s_m: float) -> tuple[float, float, float]:
    """(x, y, heading_rad) at arc length ``s_m`` along a polyline (clamped to its ends)."""
    s = arclength(poly)
    i = int(np.clip(np.searchsorted(s, s_m, side="right") - 1, 0, len(poly) - 2))
    seg = poly[i + 1] - poly[i]
    u = (min(max(s_m, 0.0), s[-1]) - s[i]) / max(s[i + 1] - s[i], 1e-12)
    p = poly[i] + u * seg
    return float(p[0]), float(p[1]), math.atan2(seg[1], seg[0])


def project(poly: np.ndarray, x_m: float, y_m: float) -> tuple[float, float]:
    """(arc length, distance) of the point of a polyline nearest to (x_m, y_m)."""
    a, b = poly[:-1], poly[1:]
    seg = b - a
    seg_len2 = np.maximum(np.einsum("ij,ij->i", seg, seg), 1e-24)
    u = np.clip(np.einsum("ij,ij->i", np.array([x_m, y_m]) - a, seg) / seg_len2, 0.0, 1.0)
    foot = a + u[:, None] * seg
    dist = np.hypot(foot[:, 0] - x_m, foot[:, 1] - y_m)
    i = int(np.argmin(dist))
    return float(arclength(poly)[i] + u[i] * math.sqrt(seg_len2[i])), float(dist[i])
