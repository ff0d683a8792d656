"""The tracker's Kalman filter, written out in floats, against the textbook filter in numpy
matrices (Bar-Shalom, Li and Kirubarajan 2001, sec. 6.3.2 and 10.4): the same estimates
within rounding, one object measured over random cycles."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from eoam_sumo.sensing.tracker import SD_FLOOR, Measurement, Tracker, TrackerSettings

CAR = (4.6, 1.8)


def _converted(m: Measurement, ox: float, oy: float) -> tuple[np.ndarray, np.ndarray]:
    c, s = math.cos(m.azimuth_rad), math.sin(m.azimuth_rad)
    z = np.array([ox + m.range_m * c, oy + m.range_m * s])
    J = np.array([[c, -m.range_m * s], [s, m.range_m * c]])
    sr, sa = max(m.range_sd_m, SD_FLOOR[0]), max(m.azimuth_sd_rad, SD_FLOOR[1])
    return z, J @ np.diag([sr * sr, sa * sa]) @ J.T


class _Reference:
    """One track of the constant-velocity filter in numpy matrices."""

    def __init__(self, cfg: TrackerSettings, t: float, m: Measurement, origin, ego_v):
        z, R = _converted(m, *origin)
        u = np.array([math.cos(m.azimuth_rad), math.sin(m.azimuth_rad)])
        n = np.array([-u[1], u[0]])
        radial = m.range_rate_mps + u @ np.asarray(ego_v)
        self.P = np.zeros((4, 4))
        self.P[:2, :2] = R
        sd_r2 = max(m.range_rate_sd_mps, SD_FLOOR[2]) ** 2
        self.P[2:, 2:] = sd_r2 * np.outer(u, u) + cfg.initial_speed_sd_mps**2 * np.outer(n, n)
        self.x = np.array([z[0], z[1], radial * u[0], radial * u[1]])
        self.t, self.q2 = t, cfg.accel_noise_mps2**2

    def predict(self, t: float) -> None:
        dt = t - self.t
        F = np.eye(4)
        F[0, 2] = F[1, 3] = dt
        a, b, c = dt**4 / 4.0, dt**3 / 2.0, dt**2
        Q = self.q2 * np.array([[a, 0, b, 0], [0, a, 0, b], [b, 0, c, 0], [0, b, 0, c]])
        self.x, self.P, self.t = F @ self.x, F @ self.P @ F.T + Q, t

    def update(self, m: Measurement, origin, ego_v) -> None:
        z, R = _converted(m, *origin)
        H = np.hstack([np.eye(2), np.zeros((2, 2))])
        K = self.P @ H.T @ np.linalg.inv(H @ self.P @ H.T + R)
        self.x = self.x + K @ (z - H @ self.x)
        self.P = (np.eye(4) - K @ H) @ self.P
        u = np.array([math.cos(m.azimuth_rad), math.sin(m.azimuth_rad)])
        h = np.array([0.0, 0.0, *u])
        s = h @ self.P @ h + max(m.range_rate_sd_mps, SD_FLOOR[2]) ** 2
        k = self.P @ h / s
        self.x = self.x + k * (m.range_rate_mps + u @ np.asarray(ego_v) - h @ self.x)
        P = self.P - np.outer(k, h @ self.P)
        self.P = 0.5 * (P + P.T)


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    range_m=st.floats(100.0, 200.0),
    azimuth_rad=st.floats(-0.5, 0.5),
    range_rate_mps=st.floats(-40.0, 10.0),
    cycle_s=st.floats(0.02, 0.2),
)
def test_float_filter_equals_the_matrix_filter(seed, range_m, azimuth_rad, range_rate_mps, cycle_s):
    rng = np.random.default_rng(seed)
    cfg = TrackerSettings()
    tracker = Tracker(cfg)
    reference = None
    ego_v = (float(rng.uniform(0.0, 40.0)), float(rng.uniform(-1.0, 1.0)))
    for k in range(12):
        t = k * cycle_s
        origin = (ego_v[0] * t, ego_v[1] * t)
        sd = (rng.uniform(0.05, 0.5), rng.uniform(0.0005, 0.005), rng.uniform(0.02, 0.2))
        noise = 0.5 * np.asarray(sd) * rng.standard_normal(3)
        m = Measurement(
            range_m + range_rate_mps * t + noise[0],
            azimuth_rad + noise[1],
            range_rate_mps + noise[2],
            *map(float, sd),
            2.3,
            0.0,
            *CAR,
        )
        tracker.update(t, [m], origin, ego_v)
        if reference is None:
            reference = _Reference(cfg, t, m, origin, ego_v)
            continue
        reference.predict(t)
        reference.update(m, origin, ego_v)
        (track,) = tracker.confirmed()
        got = [track.x_m, track.y_m, track.vx_mps, track.vy_mps]
        assert got == pytest.approx(list(reference.x), rel=1e-9, abs=1e-9)
