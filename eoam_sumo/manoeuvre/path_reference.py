"""Manoeuvre references sampled once, at the trigger, from a lookup-table trajectory.

The lookup tables (paper sec. 8.2) give the lane-change path y, path yaw, path curvature and
the optimised longitudinal acceleration against the differential x-position dx since the
trigger, for the trigger speed and friction. A ``PathReference`` stores them on a uniform dx
grid as plain floats, scaled from the table's lane-change height to the wanted one (y, yaw and
curvature scale together), so that a lookup in the 10 ms loop is one index and one blend. The
planned speed follows from the acceleration profile: v(dx)^2 = v0^2 + 2 int_0^dx ax.

A time-optimal escape (``MinTimeShift``) is a lateral motion in time, laid out along the road
at the speed it began with. While the ego brakes, following it by the distance travelled
would stretch it in time. Such a path is followed in time instead (``pace_mps``): the ego is
at ``dx = pace t`` on it, ``t`` after it began, so that its lateral motion keeps the
duration predicted for it. The course and curvature are re-timed to the ego's speed
(``retimed``): the lateral speed v_y and acceleration a_y at that time, over the ego's speed v
(slope v_y / v, curvature a_y / v^2, eqs. 7-13). Below ``MIN_PACE_RATIO`` of that pace, where
the steering could no longer turn the lateral motion into the ego's course, the path is
followed no faster than the distance travelled over that ratio.
"""

from __future__ import annotations

import math

from eoam_sumo.manoeuvre.points import PathPoint

#: A path laid out in time is followed at least this share of its pace's speed: at most this
#: many times faster along the road than the ego travels.
MIN_PACE_RATIO = 0.5


class PathReference:
    """Lateral and longitudinal reference of one manoeuvre against dx [m]."""

    __slots__ = (
        "_ax",
        "_beta",
        "_inv",
        "_k",
        "_n",
        "_steer",
        "_v",
        "_y",
        "_yaw",
        "length_m",
        "pace_mps",
        "planned_steering",
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
        pace_mps: float | None = None,
    ):
        """Sample ``traj`` (``.at(dx)``, ``.length_m``) to go from start_offset by height;
        ``height_m=None`` takes the trajectory's own lateral positions as they are;
        ``pace_mps``: the speed along the road at which it is laid out in time (None: it is
        followed by the distance travelled)."""
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
        # the planned steering and sideslip where the trajectory has them (the tables' lane
        # changes, planned with the plant's tyre), scaled with the path like the curvature
        self.planned_steering = not math.isnan(samples[0].sideslip_rad)
        if self.planned_steering:
            self._steer = [scale * float(s.steer_rad) for s in samples]
            self._beta = [scale * float(s.sideslip_rad) for s in samples]
            self._k = body_yaw_curvature(self._k, self._beta, step)
        else:
            self._steer = self._beta = [0.0] * (n + 1)
        v2 = speed_mps * speed_mps
        self._v = [speed_mps]
        for i in range(n):
            v2 += (self._ax[i] + self._ax[i + 1]) * step
            self._v.append(math.sqrt(v2) if v2 > 0.0 else 0.0)
        self.length_m = length
        self.start_offset_m = self._y[0]
        self._inv, self._n = 1.0 / step, n
        if pace_mps is not None and not (math.isfinite(pace_mps) and pace_mps > 0.0):
            raise ValueError(f"reference pace_mps={pace_mps!r} must be finite and > 0")
        self.pace_mps = pace_mps

    def progress(
        self, elapsed_s: float, travelled_m: float, speed_mps: float
    ) -> tuple[float, float]:
        """(where the ego is on the path, dx [m]; how many times faster than the ego's
        ``speed_mps`` along the road dx advances) ``elapsed_s`` after it began, having
        travelled ``travelled_m`` along the road: the distance travelled, or for a path laid
        out in time its pace's distance, at most ``travelled_m / MIN_PACE_RATIO``."""
        pace = self.pace_mps
        if pace is None:
            return travelled_m, 1.0
        timed = pace * elapsed_s
        floor = travelled_m / MIN_PACE_RATIO
        if floor < timed:
            return floor, 1.0 / MIN_PACE_RATIO
        return timed, pace / max(speed_mps, 1e-3)

    def at(self, dx_m: float) -> PathPoint:
        """The reference at ``dx_m``, held at the ends of the path."""
        u = dx_m * self._inv
        if u <= 0.0:
            i = 0
        elif u >= self._n:
            i = self._n
        else:
            i = int(u)
            w = u - i
            j = i + 1
            y, yaw, k, ax, v, st, beta = (
                self._y,
                self._yaw,
                self._k,
                self._ax,
                self._v,
                self._steer,
                self._beta,
            )
            return PathPoint(
                y[i] + w * (y[j] - y[i]),
                yaw[i] + w * (yaw[j] - yaw[i]),
                k[i] + w * (k[j] - k[i]),
                ax[i] + w * (ax[j] - ax[i]),
                v[i] + w * (v[j] - v[i]),
                st[i] + w * (st[j] - st[i]),
                beta[i] + w * (beta[j] - beta[i]),
            )
        return PathPoint(
            self._y[i],
            self._yaw[i],
            self._k[i],
            self._ax[i],
            self._v[i],
            self._steer[i],
            self._beta[i],
        )


def body_yaw_curvature(curvature_1pm: list[float], sideslip_rad: list[float], step_m: float):
    """The body's yaw angle per metre along a planned path, psi' = theta' - beta' (the
    course's curvature less the sideslip's rate, central differences on the uniform grid):
    v times it is the plan's body yaw rate, the steering law's yaw-rate reference. The
    course's rate v kappa alone differs from it by the sideslip's rate, up to 0.3 rad/s at
    165 km/h, and the yaw-rate feedback then steered against the plan's rotation."""
    n = len(sideslip_rad) - 1
    if n < 1:
        return list(curvature_1pm)
    out = []
    for i, k in enumerate(curvature_1pm):
        lo, hi = max(i - 1, 0), min(i + 1, n)
        out.append(k - (sideslip_rad[hi] - sideslip_rad[lo]) / ((hi - lo) * step_m))
    return out


def retimed(point: PathPoint, rate: float) -> PathPoint:
    """``point`` of a path laid out in time, for an ego ``rate`` times slower than its pace:
    the same lateral speed and acceleration at the ego's speed, i.e. the slope ``rate`` times
    and the curvature ``rate^2`` times the path's (with the slope's own factor,
    kappa = y'' / (1 + y'^2)^1.5)."""
    if rate == 1.0:
        return point
    slope = math.tan(point.yaw_rad)
    slope_now = rate * slope
    stretch = ((1.0 + slope * slope) / (1.0 + slope_now * slope_now)) ** 1.5
    return PathPoint(
        point.y_m,
        math.atan(slope_now),
        point.curvature_1pm * rate * rate * stretch,
        point.ax_mps2,
        point.speed_mps,
        point.steer_rad,
        point.sideslip_rad,
    )
