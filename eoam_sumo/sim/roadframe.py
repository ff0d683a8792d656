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
        self._yaw = [math.atan2(hy, hx) for hx, hy in zip(self._hx, self._hy)]
        self._kappa = [self._vertex_curvature(i) for i in range(len(self._len))]
        self._hint = 0

    @property
    def length_m(self) -> float:
        return self._s[-1]

    def project(self, x: float, y: float) -> tuple[float, float, float]:
        """(s_m, d_m, road_yaw_rad) of a point. Walks the polyline from the last answer: forward
        while the point lies past a segment's end, else backward while it lies before its start
        (beyond the ends, the first and last segments extend)."""
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
        return self._s[i] + along, ry * hx[i] - rx * hy[i], self._yaw[i]

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
        """Signed curvature (1/m) from the heading change at the nearest polyline vertex."""
        i = self._hint  # the segment of the last projection: usually the one asked for
        if self._s[i] <= s_m < self._s[i + 1]:
            return self._kappa[i]
        return self._kappa[min(max(bisect_right(self._s, s_m) - 1, 0), len(self._len) - 1)]

    def _vertex_curvature(self, i: int) -> float:
        """Curvature at the end of segment ``i`` (0 for the last segment)."""
        if i + 1 >= len(self._len):
            return 0.0
        dyaw = math.atan2(self._hy[i + 1], self._hx[i + 1]) - math.atan2(self._hy[i], self._hx[i])
        dyaw = (dyaw + math.pi) % (2.0 * math.pi) - math.pi
        return dyaw / (0.5 * (self._len[i] + self._len[i + 1]))
