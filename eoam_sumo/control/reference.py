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
        self, traj, *, start_offset_m: float, height_m: float, speed_mps: float, step_m: float
    ):
        """Sample ``traj`` (``.at(dx)``, ``.length_m``) to go from start_offset by height."""
        if not step_m > 0.0:
            raise ValueError(f"reference step_m={step_m!r} must be > 0")
        length = float(traj.length_m)
        if not (math.isfinite(length) and length > 0.0):
            raise ValueError(f"trajectory length_m={length!r} must be finite and > 0")
        n = max(math.ceil(length / step_m), 1)
        step = length / n
        samples = [traj.at(i * step) for i in range(n + 1)]
        y_end = float(samples[-1][0]) - float(samples[0][0])
        if not (math.isfinite(y_end) and abs(y_end) > 1e-6):
            raise ValueError(f"trajectory lateral travel {y_end!r} m is not usable")
        scale = height_m / y_end
        y_first = float(samples[0][0])
        self._y = [start_offset_m + scale * (float(s[0]) - y_first) for s in samples]
        self._ax = [float(s[1]) for s in samples]
        self._yaw = [scale * float(s[2]) for s in samples]
        self._k = [scale * float(s[3]) for s in samples]
        v2 = speed_mps * speed_mps
        self._v = [speed_mps]
        for i in range(n):
            v2 += (self._ax[i] + self._ax[i + 1]) * step
            self._v.append(math.sqrt(v2) if v2 > 0.0 else 0.0)
        self.length_m = length
        self.start_offset_m = start_offset_m
        self._inv, self._n = 1.0 / step, n

    def at(self, dx_m: float) -> tuple[float, float, float, float, float]:
        """(y_m, yaw_rad, curvature_1pm, ax_mps2, speed_mps), held at the ends of the path."""
        u = dx_m * self._inv
        if u <= 0.0:
            return self._y[0], self._yaw[0], self._k[0], self._ax[0], self._v[0]
        i = int(u)
        if i >= self._n:
            n = self._n
            return self._y[n], self._yaw[n], self._k[n], self._ax[n], self._v[n]
        w = u - i
        j = i + 1
        y, yaw, k, ax, v = self._y, self._yaw, self._k, self._ax, self._v
        return (
            y[i] + w * (y[j] - y[i]),
            yaw[i] + w * (yaw[j] - yaw[i]),
            k[i] + w * (k[j] - k[i]),
            ax[i] + w * (ax[j] - ax[i]),
            v[i] + w * (v[j] - v[i]),
        )


class QuinticLaneChange:
    """Unit-height quintic lane change over ``length_m`` (paper sec. 4.2), trajectory-like.

    y(u) = 10u^3 - 15u^4 + 6u^5 with u = dx / X, at constant speed (ax = 0), in the tables'
    ``at(dx) -> (y, ax, yaw, curvature, steer)`` form so that ``PathReference`` can scale it.
    ``for_lateral_accel`` picks X so that the peak lateral acceleration 5.77 h v^2 / X^2 of a
    lane change of height h at speed v equals the given value.
    """

    __slots__ = ("length_m",)

    def __init__(self, length_m: float):
        if not (math.isfinite(length_m) and length_m > 0.0):
            raise ValueError(f"quintic length_m={length_m!r} must be finite and > 0")
        self.length_m = float(length_m)

    @classmethod
    def for_lateral_accel(
        cls, height_m: float, speed_mps: float, lateral_accel_mps2: float, min_length_m: float
    ) -> QuinticLaneChange:
        peak = 10.0 * math.sqrt(3.0) / 3.0  # max |d2y/du2| of the quintic: 5.77
        length = speed_mps * math.sqrt(peak * abs(height_m) / lateral_accel_mps2)
        return cls(max(length, min_length_m))

    def at(self, dx_m: float) -> tuple[float, float, float, float, float]:
        big = self.length_m
        u = min(max(dx_m / big, 0.0), 1.0)
        u2 = u * u
        y = u2 * u * (10.0 - 15.0 * u + 6.0 * u2)
        dy = 30.0 * u2 * (1.0 - u) * (1.0 - u) / big
        ddy = 60.0 * u * (1.0 - u) * (1.0 - 2.0 * u) / (big * big)
        return y, 0.0, math.atan(dy), ddy / (1.0 + dy * dy) ** 1.5, 0.0
