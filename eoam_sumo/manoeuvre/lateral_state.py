"""The ego's lateral motion relative to the road, from an ``EgoMeasurement``: where the
lateral shifts (``quintic_shift``, ``min_time_shift``) start from."""

from __future__ import annotations

import math


def lateral_state(meas) -> tuple[float, float, float]:
    """(lateral speed [m/s], lateral acceleration [m/s^2] relative to the road, speed along
    the road [m/s]) of an ``EgoMeasurement``: lateral speed vx sin e + vy cos e, acceleration
    the measured lateral one less the road's centripetal one."""
    e = meas.e_yaw_rad
    c, s = math.cos(e), math.sin(e)
    along = max(1.0, meas.vx_mps * c - meas.vy_mps * s)
    return (
        meas.vx_mps * s + meas.vy_mps * c,
        meas.ay_mps2 - meas.road_curvature_1pm * along * along,
        along,
    )


def course_state(meas) -> tuple[float, float, float]:
    """(slope of the course relative to the road, path curvature relative to the road [1/m],
    speed along the road [m/s]) of an ``EgoMeasurement`` (from ``lateral_state``)."""
    v_lat, a_lat, along = lateral_state(meas)
    return v_lat / along, a_lat / (along * along), along
