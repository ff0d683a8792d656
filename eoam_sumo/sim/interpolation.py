"""Road users between SUMO's steps, and the ego's pose ahead, in a multi-rate co-simulation.

SUMO runs one step ``T`` (``sumo_step_s``) ahead of the EOAM's control steps (10 ms): between
its reports at ``t0`` and ``t0 + T`` each road user moves at the constant acceleration
``a = (v1 - v0) / T`` its two speeds give (SUMO's ballistic update moves it so within a step),
its speed ``v0 + a tau`` and its travel ``v0 tau + a tau^2 / 2`` along the way from its pose at
``t0`` to its pose at ``t0 + T`` (a lane change or a curve followed along the chord), its
heading turning evenly. Both reports are met exactly; position and speed are continuous.

SUMO's view of the ego at ``t0 + T`` is the ego carried on from its last control step at
constant acceleration along its heading (:func:`ego_ahead`), so that the road users' car
following and lane changes see it less than a control step old.
"""

from __future__ import annotations

import math

from eoam_sumo.world.bodies import Body

__all__ = ["between", "ego_ahead", "interpolate_reports", "travel_m"]


def travel_m(speed_mps: float, accel_mps2: float, dt_s: float) -> tuple[float, float]:
    """(distance [m], speed [m/s]) after ``dt_s`` at constant acceleration from
    ``speed_mps``, the motion ending at standstill (s = v t + a t^2 / 2, v' = v + a t; a
    braking body stops at t = -v / a and stays)."""
    end_mps = speed_mps + accel_mps2 * dt_s
    if end_mps < 0.0 <= speed_mps and accel_mps2 < 0.0:
        stop_s = -speed_mps / accel_mps2
        return 0.5 * speed_mps * stop_s, 0.0
    return speed_mps * dt_s + 0.5 * accel_mps2 * dt_s * dt_s, end_mps


def between(b0: Body, b1: Body, tau_s: float, step_s: float) -> Body:
    """A road user ``tau_s`` after SUMO reported it as ``b0``, on its way to ``b1`` reported
    ``step_s`` later (module doc); ``b1`` itself at ``tau_s >= step_s`` or when it has not
    moved."""
    if tau_s >= step_s or b0 is b1:
        return b1
    _, _, x0, y0, yaw0, v0, _, _, _, _ = b0  # see ``_BodyFields``
    vid, vclass, x1, y1, yaw1, v1, length_m, width_m, parked, _ = b1
    accel = (v1 - v0) / step_s
    whole_m = 0.5 * (v0 + v1) * step_s
    part_m = v0 * tau_s + 0.5 * accel * tau_s * tau_s
    w = part_m / whole_m if whole_m > 1e-9 else tau_s / step_s
    turn = math.remainder(yaw1 - yaw0, 2.0 * math.pi)
    return Body(
        vid,
        vclass,
        x0 + w * (x1 - x0),
        y0 + w * (y1 - y0),
        yaw0 + turn * (tau_s / step_s),
        v0 + accel * tau_s,
        length_m,
        width_m,
        parked,
    )


def interpolate_reports(
    report0: list[Body], report1: list[Body], tau_s: float, step_s: float
) -> list[Body]:
    """The road users of SUMO's later report ``report1`` ``tau_s`` after the earlier one
    (:func:`between`); one not in ``report0`` (just departed or come within reach) as
    ``report1`` has it."""
    if tau_s >= step_s:
        return report1
    earlier = {b.vid: b for b in report0}
    out = []
    for b1 in report1:
        b0 = earlier.get(b1.vid)
        out.append(b1 if b0 is None else between(b0, b1, tau_s, step_s))
    return out


def ego_ahead(x: list, accel_mps2: float, ahead_s: float) -> tuple[float, float, float, float]:
    """(x [m], y [m], yaw [rad], speed [m/s]) of the ego ``ahead_s`` after plant state ``x``
    (X, Y, yaw, vx, vy, yaw rate, ...): carried on along its heading at constant acceleration
    (stopping at standstill, :func:`travel_m`), its heading at its yaw rate."""
    dist, speed = travel_m(max(x[3], 0.0), accel_mps2, ahead_s)
    yaw = x[2]
    return x[0] + dist * math.cos(yaw), x[1] + dist * math.sin(yaw), yaw + x[5] * ahead_s, speed
