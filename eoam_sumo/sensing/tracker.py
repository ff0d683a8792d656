"""Multi-object tracker: radar detections (range, azimuth, range rate) to confirmed tracks.

A constant-velocity Kalman filter per track in the network's x-y frame (state: position of
the reflection point and its velocity), the textbook design of Bar-Shalom, Li and
Kirubarajan (2001, *Estimation with Applications to Tracking and Navigation*, sec. 6.3.2,
discrete white-noise acceleration model):

* predict: F = [[I, dt I], [0, I]], Q = q^2 [[dt^4/4 I, dt^3/2 I], [dt^3/2 I, dt^2 I]];
* position update with the polar measurement converted to x-y and its covariance
  R = J diag(sigma_r^2, sigma_az^2) J^T (converted-measurement filter, ibid. sec. 10.4);
* range-rate update, linear once the line of sight u is fixed at the measured azimuth:
  rr + u . v_ego = u . v (H = [0, 0, u_x, u_y]);
* gating: Mahalanobis distance of the position innovation below ``gate_chi2`` (chi-square,
  2 degrees of freedom); association: global nearest neighbour, greedy by distance;
* life cycle: a new detection opens a tentative track, confirmed after ``confirm_hits``
  hits within its first ``confirm_window`` cycles (M-of-N), deleted after
  ``delete_misses`` consecutive misses (a tentative one as soon as it can no longer be
  confirmed).

Only confirmed tracks are reported. Each track keeps what its last detection said about the
object's extent (the offset from the reflection point to the box centre, length, width), as
an object-list radar reports it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from mypy_extensions import mypyc_attr

from eoam_sumo.errors import InputError

#: chi-square, 2 degrees of freedom, 99 %: the gate of the position innovation
GATE_CHI2_99 = 9.21
#: Smallest measurement standard deviations the filter assumes (range [m], azimuth [rad],
#: range rate [m/s]): keeps its gains finite for a noise-free radar.
SD_FLOOR = (1e-3, 1e-6, 1e-3)


@mypyc_attr(native_class=False)  # a Python dataclass: pickled, replaced
@dataclass(frozen=True)
class TrackerSettings:
    """Tracker tuning (values assumed; reasons in the comments)."""

    accel_noise_mps2: float = 4.0  # q: white acceleration; half of an 8 m/s^2 stop [m/s^2]
    gate_chi2: float = GATE_CHI2_99  # position innovation gate [-]
    confirm_hits: int = 2  # M of the M-of-N confirmation
    confirm_window: int = 3  # N: cycles from the first detection
    delete_misses: int = 3  # consecutive missed cycles that delete a confirmed track
    initial_speed_sd_mps: float = 30.0  # prior sd of the unmeasured (tangential) velocity

    def __post_init__(self) -> None:
        for name in ("accel_noise_mps2", "gate_chi2", "initial_speed_sd_mps"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                raise InputError(f"tracker {name} = {value!r} must be > 0")
        if not 1 <= self.confirm_hits <= self.confirm_window or self.delete_misses < 1:
            raise InputError(
                "tracker: need 1 <= confirm_hits <= confirm_window and delete_misses >= 1"
            )


class Measurement(NamedTuple):
    """One radar detection, polar from the radar at (ox, oy), plus the object's extent."""

    range_m: float
    azimuth_rad: float  # of the line of sight in the network frame (CCW from +x)
    range_rate_mps: float
    range_sd_m: float
    azimuth_sd_rad: float
    range_rate_sd_mps: float
    centre_dx_m: float  # box centre minus the reflection point
    centre_dy_m: float
    length_m: float
    width_m: float


class TrackState(NamedTuple):
    """A confirmed track as reported: reflection point, velocity, extent."""

    track_id: int
    x_m: float
    y_m: float
    vx_mps: float
    vy_mps: float
    centre_dx_m: float
    centre_dy_m: float
    length_m: float
    width_m: float


class _Track:
    __slots__ = ("P", "age", "confirmed", "extent", "hits", "misses", "t", "tid", "x")

    def __init__(self, tid: int, x: np.ndarray, P: np.ndarray, t: float, extent: tuple):
        self.tid, self.x, self.P, self.t = tid, x, P, t
        self.hits, self.age, self.misses, self.confirmed = 1, 1, 0, False  # age in cycles
        self.extent = extent


def _converted(m: Measurement, ox: float, oy: float) -> tuple[np.ndarray, np.ndarray]:
    """x-y position of a polar measurement and its covariance J diag(sr^2, sa^2) J^T."""
    c, s = math.cos(m.azimuth_rad), math.sin(m.azimuth_rad)
    z = np.array([ox + m.range_m * c, oy + m.range_m * s])
    J = np.array([[c, -m.range_m * s], [s, m.range_m * c]])
    sr, sa = max(m.range_sd_m, SD_FLOOR[0]), max(m.azimuth_sd_rad, SD_FLOOR[1])
    R = J @ np.diag([sr * sr, sa * sa]) @ J.T
    return z, R


class Tracker:
    """Tracks from batches of detections; :meth:`update` once per radar cycle."""

    def __init__(self, settings: TrackerSettings = TrackerSettings()):
        self.settings = settings
        self._tracks: list[_Track] = []
        self._next_id = 1

    def _predict(self, track: _Track, t: float) -> None:
        dt = t - track.t
        if dt <= 0.0:
            return
        F = np.eye(4)
        F[0, 2] = F[1, 3] = dt
        q2 = self.settings.accel_noise_mps2**2
        a, b, c = dt**4 / 4.0, dt**3 / 2.0, dt**2
        Q = q2 * np.array([[a, 0, b, 0], [0, a, 0, b], [b, 0, c, 0], [0, b, 0, c]])
        track.x = F @ track.x
        track.P = F @ track.P @ F.T + Q
        track.t = t

    @staticmethod
    def _update(
        track: _Track, z: np.ndarray, R: np.ndarray, m: Measurement, ego_v: tuple[float, float]
    ) -> None:
        H = np.zeros((2, 4))
        H[0, 0] = H[1, 1] = 1.0
        S = H @ track.P @ H.T + R
        K = track.P @ H.T @ np.linalg.inv(S)
        track.x = track.x + K @ (z - H @ track.x)
        track.P = (np.eye(4) - K @ H) @ track.P
        ux, uy = math.cos(m.azimuth_rad), math.sin(m.azimuth_rad)
        h = np.array([0.0, 0.0, ux, uy])
        s = float(h @ track.P @ h) + max(m.range_rate_sd_mps, SD_FLOOR[2]) ** 2
        k = track.P @ h / s
        innovation = m.range_rate_mps + ux * ego_v[0] + uy * ego_v[1] - float(h @ track.x)
        track.x = track.x + k * innovation
        track.P = track.P - np.outer(k, h @ track.P)
        track.P = 0.5 * (track.P + track.P.T)

    def update(
        self,
        t: float,
        measurements: list[Measurement],
        origin: tuple[float, float],
        ego_velocity: tuple[float, float],
    ) -> None:
        """One radar cycle: the detections of the scan at time ``t`` seen from ``origin``
        while the ego moved at ``ego_velocity`` (network frame)."""
        st = self.settings
        for track in self._tracks:
            self._predict(track, t)
        converted = [_converted(m, *origin) for m in measurements]
        pairs = []
        for i, track in enumerate(self._tracks):
            P = track.P[:2, :2]
            for j, (z, R) in enumerate(converted):
                nu = z - track.x[:2]
                d2 = float(nu @ np.linalg.solve(P + R, nu))
                if d2 <= st.gate_chi2:
                    pairs.append((d2, i, j))
        pairs.sort()
        used_tracks, used_meas = set(), set()
        for _, i, j in pairs:
            if i in used_tracks or j in used_meas:
                continue
            used_tracks.add(i)
            used_meas.add(j)
            track, m = self._tracks[i], measurements[j]
            self._update(track, *converted[j], m, ego_velocity)
            track.extent = (m.centre_dx_m, m.centre_dy_m, m.length_m, m.width_m)
            track.hits += 1
            track.misses = 0
        alive = []
        for i, track in enumerate(self._tracks):
            track.age += 1
            if i not in used_tracks:
                track.misses += 1
            if not track.confirmed and track.hits >= st.confirm_hits:
                track.confirmed = True
            if track.confirmed:
                if track.misses < st.delete_misses:
                    alive.append(track)
            elif track.hits + max(st.confirm_window - track.age, 0) >= st.confirm_hits:
                alive.append(track)  # tentative, and can still be confirmed
        for j, m in enumerate(measurements):
            if j not in used_meas:
                alive.append(self._new_track(t, m, converted[j], ego_velocity))
        self._tracks = alive

    def _new_track(self, t: float, m: Measurement, zR: tuple, ego_v: tuple) -> _Track:
        z, R = zR
        ux, uy = math.cos(m.azimuth_rad), math.sin(m.azimuth_rad)
        radial = m.range_rate_mps + ux * ego_v[0] + uy * ego_v[1]
        P = np.zeros((4, 4))
        P[:2, :2] = R
        sd_t2 = self.settings.initial_speed_sd_mps**2
        sd_r2 = max(m.range_rate_sd_mps, SD_FLOOR[2]) ** 2
        u = np.array([ux, uy])
        n = np.array([-uy, ux])
        P[2:, 2:] = sd_r2 * np.outer(u, u) + sd_t2 * np.outer(n, n)
        x = np.array([z[0], z[1], radial * ux, radial * uy])
        track = _Track(
            self._next_id, x, P, t, (m.centre_dx_m, m.centre_dy_m, m.length_m, m.width_m)
        )
        self._next_id += 1
        if self.settings.confirm_hits <= 1:
            track.confirmed = True
        return track

    def confirmed(self) -> list[TrackState]:
        """The confirmed tracks, as of the last update."""
        return [
            TrackState(
                tr.tid, float(tr.x[0]), float(tr.x[1]), float(tr.x[2]), float(tr.x[3]), *tr.extent
            )
            for tr in self._tracks
            if tr.confirmed
        ]
