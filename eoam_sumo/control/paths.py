"""Manoeuvre references sampled once, at the trigger, from a lookup-table trajectory.

The lookup tables (paper sec. 8.2) give the lane-change path y, path yaw, path curvature and
the optimised longitudinal acceleration against the differential x-position dx since the
trigger, for the trigger speed and friction. A ``PathReference`` stores them on a uniform dx
grid as plain floats, scaled from the table's lane-change height to the wanted one (y, yaw and
curvature scale together), so that a lookup in the 10 ms loop is one index and one blend. The
planned speed follows from the acceleration profile: v(dx)^2 = v0^2 + 2 int_0^dx ax.
"""

from __future__ import annotations

import math
from typing import NamedTuple

from eoam_sumo.offline.tables import TrajectoryPoint


class PathPoint(NamedTuple):
    """A sampled manoeuvre reference at one differential x-position."""

    y_m: float  # lateral position (road frame, left positive)
    yaw_rad: float  # path direction of travel relative to the road
    curvature_1pm: float  # signed path curvature, left positive
    ax_mps2: float  # planned longitudinal acceleration
    speed_mps: float  # planned speed


# ``tuple.__new__(NamedTuple, values)`` builds a named tuple in ~70 ns, its constructor in
# ~160 ns: used where a result is built at every step
_new = tuple.__new__


class PathReference:
    """Lateral and longitudinal reference of one manoeuvre against dx [m]."""

    __slots__ = (
        "_ax",
        "_inv",
        "_k",
        "_n",
        "_v",
        "_y",
        "_yaw",
        "length_m",
        "start_offset_m",
    )

    def __init__(
        self,
        traj,
        *,
        start_offset_m: float,
        height_m: float | None,
        speed_mps: float,
        step_m: float,
    ):
        """Sample ``traj`` (``.at(dx)``, ``.length_m``) to go from start_offset by height;
        ``height_m=None`` takes the trajectory's own lateral positions as they are."""
        if not step_m > 0.0:
            raise ValueError(f"reference step_m={step_m!r} must be > 0")
        length = float(traj.length_m)
        if not (math.isfinite(length) and length > 0.0):
            raise ValueError(f"trajectory length_m={length!r} must be finite and > 0")
        n = max(math.ceil(length / step_m), 1)
        step = length / n
        samples = [traj.at(i * step) for i in range(n + 1)]
        if height_m is None:
            scale, y_first, start_offset_m = 1.0, 0.0, 0.0
        else:
            y_end = float(samples[-1].y_m) - float(samples[0].y_m)
            if not (math.isfinite(y_end) and abs(y_end) > 1e-6):
                raise ValueError(f"trajectory lateral travel {y_end!r} m is not usable")
            scale = height_m / y_end
            y_first = float(samples[0].y_m)
        self._y = [start_offset_m + scale * (float(s.y_m) - y_first) for s in samples]
        self._ax = [float(s.ax_mps2) for s in samples]
        self._yaw = [scale * float(s.yaw_rad) for s in samples]
        self._k = [scale * float(s.curvature_1pm) for s in samples]
        v2 = speed_mps * speed_mps
        self._v = [speed_mps]
        for i in range(n):
            v2 += (self._ax[i] + self._ax[i + 1]) * step
            self._v.append(math.sqrt(v2) if v2 > 0.0 else 0.0)
        self.length_m = length
        self.start_offset_m = self._y[0]
        self._inv, self._n = 1.0 / step, n

    def at(self, dx_m: float) -> PathPoint:
        """The reference at ``dx_m``, held at the ends of the path."""
        u = dx_m * self._inv
        if u <= 0.0:
            return PathPoint(self._y[0], self._yaw[0], self._k[0], self._ax[0], self._v[0])
        i = int(u)
        if i >= self._n:
            n = self._n
            return PathPoint(self._y[n], self._yaw[n], self._k[n], self._ax[n], self._v[n])
        w = u - i
        j = i + 1
        y, yaw, k, ax, v = self._y, self._yaw, self._k, self._ax, self._v
        return _new(PathPoint, (
            y[i] + w * (y[j] - y[i]),
            yaw[i] + w * (yaw[j] - yaw[i]),
            k[i] + w * (k[j] - k[i]),
            ax[i] + w * (ax[j] - ax[i]),
            v[i] + w * (v[j] - v[i]),
        ))


PEAK_SAMPLES = 200  # intervals over which a shift's peak curvature is sampled
_PEAK_U = [i / PEAK_SAMPLES for i in range(PEAK_SAMPLES + 1)]


class QuinticShift:
    """Quintic from offset ``y0`` with slope ``slope0`` to offset ``y1`` (paper sec. 4.2).

    y(u) = y0 + P u + c3 u^3 + c4 u^4 + c5 u^5 with u = dx / X and P = slope0 X: the start
    keeps the ego's heading relative to the road (zero curvature), the end is y = y1 with
    y' = y'' = 0. With slope0 = 0 it is the paper's lane change
    y0 + (y1 - y0) (10u^3 - 15u^4 + 6u^5). Given at constant speed (ax = 0) in the tables'
    ``at(dx) -> TrajectoryPoint`` form, in absolute lateral positions
    (``PathReference(..., height_m=None)``).
    """

    __slots__ = ("_c", "length_m")

    def __init__(self, y0_m: float, slope0: float, y1_m: float, length_m: float):
        if not (math.isfinite(length_m) and length_m > 0.0):
            raise ValueError(f"quintic length_m={length_m!r} must be finite and > 0")
        if not (math.isfinite(y0_m) and math.isfinite(slope0) and math.isfinite(y1_m)):
            raise ValueError(f"quintic y0={y0_m!r}, slope0={slope0!r}, y1={y1_m!r} not finite")
        p = slope0 * length_m
        e, f = y1_m - y0_m - p, -p  # what the u^3..u^5 terms must add to y and dy/du at u = 1
        self._c = (y0_m, p, 10.0 * e - 4.0 * f, -15.0 * e + 7.0 * f, 6.0 * e - 3.0 * f)
        self.length_m = float(length_m)

    def _curvature_samples(self):
        """|y''| at the ``PEAK_SAMPLES + 1`` sample points, per metre^2 of length."""
        _, _, c3, c4, c5 = self._c
        big2 = self.length_m * self.length_m
        return (abs(6.0 * c3 * u + 12.0 * c4 * u * u + 20.0 * c5 * u * u * u) / big2
                for u in _PEAK_U)

    def peak_curvature_1pm(self) -> float:
        """Largest |y''| along the path (sampled), the lateral acceleration per v^2."""
        return max(self._curvature_samples())

    def _peak_exceeds(self, limit_1pm: float) -> bool:
        """``peak_curvature_1pm() > limit_1pm``, stopping at the first sample over the limit."""
        return any(k > limit_1pm for k in self._curvature_samples())

    @classmethod
    def for_lateral_accel(
        cls,
        y0_m: float,
        slope0: float,
        y1_m: float,
        speed_mps: float,
        lateral_accel_mps2: float,
        min_length_m: float,
    ) -> QuinticShift:
        """The shortest shift (on a 2 % length grid, not below ``min_length_m``) whose peak
        lateral acceleration v^2 |y''| is within ``lateral_accel_mps2``."""
        if not (lateral_accel_mps2 > 0.0 and min_length_m > 0.0):
            raise ValueError("lateral_accel_mps2 and min_length_m must be > 0")
        limit = lateral_accel_mps2 / max(speed_mps * speed_mps, 1e-9)
        level = math.sqrt(10.0 * math.sqrt(3.0) / 3.0 * abs(y1_m - y0_m) / limit)  # slope0 = 0
        length = max(min_length_m, 0.5 * level)
        while (traj := cls(y0_m, slope0, y1_m, length))._peak_exceeds(limit):
            length *= 1.02
        return traj

    def at(self, dx_m: float) -> TrajectoryPoint:
        big = self.length_m
        u = min(max(dx_m / big, 0.0), 1.0)
        y0, p, c3, c4, c5 = self._c
        u2 = u * u
        y = y0 + u * (p + u2 * (c3 + u * (c4 + u * c5)))
        dy = (p + u2 * (3.0 * c3 + u * (4.0 * c4 + 5.0 * u * c5))) / big
        ddy = u * (6.0 * c3 + u * (12.0 * c4 + 20.0 * u * c5)) / (big * big)
        return TrajectoryPoint(y, 0.0, math.atan(dy), ddy / (1.0 + dy * dy) ** 1.5, 0.0)
