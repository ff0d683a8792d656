"""Road users between SUMO's steps, in a multi-rate co-simulation.

SUMO reports every road user's pose and speed at its own step ``T`` (``sumo_step_s``); the
EOAM senses, decides and checks contact every control step (10 ms). Between two SUMO steps a
road user is carried on from SUMO's last report at constant acceleration along its heading
(the acceleration SUMO gave it over its last step, ``(v(t) - v(t - T)) / T``), its heading
kept and its speed stopped at 0 (a braking road user stands, it does not reverse). At the
next SUMO step SUMO's own report replaces the estimate.
"""

from __future__ import annotations

import math

from eoam_sumo.world.bodies import Body

__all__ = ["accelerations", "advance_bodies", "advance_body", "travel_m"]


def travel_m(speed_mps: float, accel_mps2: float, dt_s: float) -> tuple[float, float]:
    """(distance [m], speed [m/s]) after ``dt_s`` at constant acceleration from
    ``speed_mps``, the motion ending at standstill (s = v t + a t^2 / 2, v' = v + a t; a
    braking road user stops at t = -v / a and stays)."""
    end_mps = speed_mps + accel_mps2 * dt_s
    if end_mps < 0.0:
        if accel_mps2 >= 0.0:  # moving backwards and not braking: carried on as it is
            return speed_mps * dt_s + 0.5 * accel_mps2 * dt_s * dt_s, end_mps
        stop_s = -speed_mps / accel_mps2
        return 0.5 * speed_mps * stop_s, 0.0
    return speed_mps * dt_s + 0.5 * accel_mps2 * dt_s * dt_s, end_mps


def advance_body(body: Body, accel_mps2: float, dt_s: float) -> Body:
    """``body`` ``dt_s`` after SUMO reported it, at ``accel_mps2`` along its heading; the
    same object when it neither moves nor accelerates (a parked or standing road user)."""
    if body.speed_mps == 0.0 and accel_mps2 <= 0.0:
        return body
    dist, speed = travel_m(body.speed_mps, accel_mps2, dt_s)
    yaw = body.yaw_rad
    return Body(
        body.vid,
        body.vclass,
        body.x_m + dist * math.cos(yaw),
        body.y_m + dist * math.sin(yaw),
        yaw,
        speed,
        body.length_m,
        body.width_m,
        body.parked,
    )


def accelerations(before: list, now: list, dt_s: float) -> dict[str, float]:
    """Each road user's acceleration over SUMO's last step of ``dt_s``: its speed change
    between the two reports (0 for one not reported before, or parked)."""
    speeds = {b.vid: b.speed_mps for b in before}
    out: dict[str, float] = {}
    for b in now:
        v0 = speeds.get(b.vid)
        out[b.vid] = 0.0 if v0 is None or b.parked else (b.speed_mps - v0) / dt_s
    return out


def advance_bodies(bodies: list, accel: dict[str, float], dt_s: float) -> list:
    """Every body of SUMO's last report carried on by ``dt_s`` (:func:`advance_body`)."""
    return [advance_body(b, accel.get(b.vid, 0.0), dt_s) for b in bodies]
