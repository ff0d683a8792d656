"""The standards' figures, computed from time series: pure functions of arrays.

Every function takes plain numpy arrays (time [s], speeds [m/s], ...), so each can be checked
on hand-made series with a closed-form answer. Clauses: ``clauses.py``.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from eoam_sumo.params import G_MPS2

KMH_PER_MPS = 3.6

STOP_SPEED_MPS = 0.01
"""Below this speed the vehicle counts as stopped (ours: a stop in the simulation)."""

LOCK_SLIP = 0.9
"""An axle counts as locked when its wheel speed is below ``1 - LOCK_SLIP`` of the body
speed (ours: a locked wheel turns at 0; wheel-spin states pass through the intermediate slips
in a fraction of a second)."""

LOCK_MIN_SPEED_MPS = 1.0
"""Below this body speed no lock is judged (the slip of a stopping wheel is undefined)."""


def stopping_distance_limit_m(speed_kmh: float) -> float:
    """R13-H Annex 3 para. 2.1.1: ``0.1 v + 0.0060 v^2`` [m] for ``v`` in km/h."""
    return 0.1 * speed_kmh + 0.0060 * speed_kmh * speed_kmh


def path_length_m(x_m: np.ndarray, y_m: np.ndarray) -> np.ndarray:
    """Distance travelled along the path at each sample, from the first."""
    steps = np.hypot(np.diff(x_m), np.diff(y_m))
    return np.concatenate(([0.0], np.cumsum(steps)))


def stop_time_s(time_s: np.ndarray, speed_mps: np.ndarray, after_s: float) -> float | None:
    """First time after ``after_s`` at which the speed is at most ``STOP_SPEED_MPS``, linearly
    interpolated; None when the vehicle never stops."""
    idx = np.flatnonzero((time_s >= after_s) & (speed_mps <= STOP_SPEED_MPS))
    if idx.size == 0:
        return None
    k = int(idx[0])
    if k == 0 or speed_mps[k - 1] <= STOP_SPEED_MPS:
        return float(time_s[k])
    frac = (speed_mps[k - 1] - STOP_SPEED_MPS) / (speed_mps[k - 1] - speed_mps[k])
    return float(time_s[k - 1] + frac * (time_s[k] - time_s[k - 1]))


def distance_between_m(
    time_s: np.ndarray, distance_m: np.ndarray, start_s: float, end_s: float
) -> float:
    """Distance travelled between two times (linear interpolation)."""
    return float(np.interp(end_s, time_s, distance_m) - np.interp(start_s, time_s, distance_m))


def mfdd_mps2(speed_mps: np.ndarray, distance_m: np.ndarray, v0_mps: float) -> float | None:
    """Mean fully developed deceleration (R13-H Annex 3 para. 1.1.2): the deceleration averaged
    over distance from ``vb = 0.8 v0`` to ``ve = 0.1 v0``, ``(vb^2 - ve^2) / (2 (se - sb))``
    in SI units (the regulation's ``25.92`` is ``2 * 3.6^2`` for km/h). ``speed_mps`` must
    fall monotonically over that interval; None when it does not reach ``ve``."""
    vb_mps, ve_mps = 0.8 * v0_mps, 0.1 * v0_mps
    sb_m = _distance_at_speed(speed_mps, distance_m, vb_mps)
    se_m = _distance_at_speed(speed_mps, distance_m, ve_mps)
    if sb_m is None or se_m is None or se_m <= sb_m:
        return None
    return (vb_mps * vb_mps - ve_mps * ve_mps) / (2.0 * (se_m - sb_m))


def _distance_at_speed(speed_mps: np.ndarray, distance_m: np.ndarray, v_mps: float) -> float | None:
    idx = np.flatnonzero(speed_mps <= v_mps)
    if idx.size == 0 or idx[0] == 0:
        return None
    k = int(idx[0])
    frac = (speed_mps[k - 1] - v_mps) / (speed_mps[k - 1] - speed_mps[k])
    return float(distance_m[k - 1] + frac * (distance_m[k] - distance_m[k - 1]))


def locked(wheel_speed_mps: np.ndarray, vx_mps: np.ndarray) -> np.ndarray:
    """Per sample: is the axle locked (``LOCK_SLIP``; not judged below ``LOCK_MIN_SPEED_MPS``)."""
    return (vx_mps > LOCK_MIN_SPEED_MPS) & (wheel_speed_mps < (1.0 - LOCK_SLIP) * vx_mps)


def first_time_s(time_s: np.ndarray, flags: np.ndarray) -> float | None:
    """Time of the first True sample, None when there is none."""
    idx = np.flatnonzero(flags)
    return float(time_s[idx[0]]) if idx.size else None


class LockOrder(NamedTuple):
    """Which axle locked first in a brake ramp, and the braking rates z = decel / g at which
    each axle locked (the highest rate reached before the lock; None: never locked)."""

    first: str  # "front", "rear", "both" (same sample) or "none"
    rate_front: float | None
    rate_rear: float | None

    def passes(self, rate_min: float, rate_max: float) -> bool:
        """R13-H Annex 5: between braking rates ``rate_min`` and ``rate_max`` no rear lock
        without the front locked too (front first or together)."""
        if self.rate_rear is None or self.first in ("front", "both"):
            return True
        front = math.inf if self.rate_front is None else self.rate_front
        return not (self.rate_rear <= rate_max and front > rate_min)


def lock_order(
    time_s: np.ndarray, ax_mps2: np.ndarray, front_locked: np.ndarray, rear_locked: np.ndarray
) -> LockOrder:
    """The lock order of a brake ramp from the lock flags of each axle per sample."""
    rate = np.maximum.accumulate(-ax_mps2 / G_MPS2)
    t_front, t_rear = first_time_s(time_s, front_locked), first_time_s(time_s, rear_locked)

    def rate_at(t_lock: float | None) -> float | None:
        if t_lock is None:
            return None
        k = int(np.searchsorted(time_s, t_lock))
        return float(rate[max(k - 1, 0)])

    if t_front is None and t_rear is None:
        first = "none"
    elif t_rear is None or (t_front is not None and t_front < t_rear):
        first = "front"
    elif t_front is None or t_rear < t_front:
        first = "rear"
    else:
        first = "both"
    return LockOrder(first, rate_at(t_front), rate_at(t_rear))


def crossing_value(
    x: np.ndarray, y: np.ndarray, y_target: float, *, start: int = 0
) -> float | None:
    """``x`` where ``y`` first reaches ``y_target`` from below after index ``start``, linearly
    interpolated; None if it never does."""
    idx = np.flatnonzero(y[start:] >= y_target)
    if idx.size == 0:
        return None
    k = int(idx[0]) + start
    if k == 0 or y[k] == y[k - 1]:
        return float(x[k])
    frac = (y_target - y[k - 1]) / (y[k] - y[k - 1])
    return float(x[k - 1] + frac * (x[k] - x[k - 1]))
