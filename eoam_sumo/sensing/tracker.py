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
    """A track's state ``x`` (x, y, vx, vy) and covariance ``P`` (4 x 4, row-major), in
    plain floats: the filter's algebra written out (a 4-state filter through numpy costs
    more in calls than in arithmetic)."""

    __slots__ = ("P", "age", "confirmed", "extent", "hits", "misses", "t", "tid", "x")

    def __init__(self, tid: int, x: list[float], P: list[float], t: float, extent: tuple):
        self.tid, self.x, self.P, self.t = tid, x, P, t
        self.hits, self.age, self.misses, self.confirmed = 1, 1, 0, False  # age in cycles
        self.extent = extent


def _converted(m: Measurement, ox: float, oy: float) -> tuple[float, float, float, float, float]:
    """x-y position of a polar measurement and its covariance J diag(sr^2, sa^2) J^T, with
    J = [[c, -r s], [s, r c]]: (zx, zy, R_xx, R_xy, R_yy)."""
    c, s = math.cos(m.azimuth_rad), math.sin(m.azimuth_rad)
    r = m.range_m
    sr, sa = max(m.range_sd_m, SD_FLOOR[0]), max(m.azimuth_sd_rad, SD_FLOOR[1])
    vr, va = sr * sr, sa * sa
    rs, rc = r * s, r * c
    return (
        ox + r * c,
        oy + r * s,
        c * c * vr + rs * rs * va,
        c * s * vr - rs * rc * va,
        s * s * vr + rc * rc * va,
    )


def _predicted(P: list[float], dt: float, q2: float) -> list[float]:
    """F P F^T + Q for F = [[I, dt I], [0, I]] and the white-acceleration Q (module doc)."""
    fp = [P[k] + dt * P[k + 8] if k < 8 else P[k] for k in range(16)]  # F P: rows 0, 1
    out = [0.0] * 16
    for row in range(4):
        i = 4 * row
        out[i] = fp[i] + dt * fp[i + 2]  # (F P) F^T: columns 0, 1
        out[i + 1] = fp[i + 1] + dt * fp[i + 3]
        out[i + 2] = fp[i + 2]
        out[i + 3] = fp[i + 3]
    a, b, c = q2 * (dt**4 / 4.0), q2 * (dt**3 / 2.0), q2 * dt**2
    for k, q in ((0, a), (5, a), (2, b), (7, b), (8, b), (13, b), (10, c), (15, c)):
        out[k] += q
    return out


def _innovation(
    track: _Track, z: tuple[float, float, float, float, float]
) -> tuple[float, float, float, float, float, float]:
    """The position innovation of the converted measurement ``z`` (``_converted``), H = [I 0]:
    its covariance S = P_pp + R (s00, s01, s10, s11) and nu = z - H x (nu0, nu1)."""
    P, x = track.P, track.x
    return P[0] + z[2], P[1] + z[3], P[4] + z[3], P[5] + z[4], z[0] - x[0], z[1] - x[1]


def _position_update(track: _Track, z: tuple[float, float, float, float, float]) -> None:
    """The position update with the converted measurement ``z`` (``_innovation``):
    K = P H^T S^-1, x += K nu, P -= K H P."""
    P, x = track.P, track.x
    s00, s01, s10, s11, nu0, nu1 = _innovation(track, z)
    det = s00 * s11 - s01 * s10
    i00, i01, i10, i11 = s11 / det, -s01 / det, -s10 / det, s00 / det
    K = []
    for row in range(4):
        p0, p1 = P[4 * row], P[4 * row + 1]
        K.append((p0 * i00 + p1 * i10, p0 * i01 + p1 * i11))
    track.x = [x[r] + K[r][0] * nu0 + K[r][1] * nu1 for r in range(4)]
    track.P = [
        P[4 * r + c] - (K[r][0] * P[c] + K[r][1] * P[4 + c]) for r in range(4) for c in range(4)
    ]


def _range_rate_update(track: _Track, m: Measurement, ego_v: tuple[float, float]) -> None:
    """The range-rate update, h = [0, 0, u_x, u_y] at the measured azimuth; then P made
    symmetric."""
    P, x = track.P, track.x
    ux, uy = math.cos(m.azimuth_rad), math.sin(m.azimuth_rad)
    ph = [ux * P[4 * r + 2] + uy * P[4 * r + 3] for r in range(4)]  # P h
    hp = [ux * P[8 + c] + uy * P[12 + c] for c in range(4)]  # h P
    s = ux * ph[2] + uy * ph[3] + max(m.range_rate_sd_mps, SD_FLOOR[2]) ** 2
    k = [v / s for v in ph]
    innovation = m.range_rate_mps + ux * ego_v[0] + uy * ego_v[1] - (ux * x[2] + uy * x[3])
    track.x = [x[r] + k[r] * innovation for r in range(4)]
    new = [P[4 * r + c] - k[r] * hp[c] for r in range(4) for c in range(4)]
    track.P = [0.5 * (new[4 * r + c] + new[4 * c + r]) for r in range(4) for c in range(4)]


def _gate_distance(track: _Track, z: tuple[float, float, float, float, float]) -> float:
    """Squared Mahalanobis distance of the position innovation, nu^T S^-1 nu
    (``_innovation``)."""
    a, b, c, d, nu0, nu1 = _innovation(track, z)
    det = a * d - b * c
    return (nu0 * (d * nu0 - b * nu1) + nu1 * (a * nu1 - c * nu0)) / det


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
        x = track.x
        track.x = [x[0] + dt * x[2], x[1] + dt * x[3], x[2], x[3]]
        track.P = _predicted(track.P, dt, self.settings.accel_noise_mps2**2)
        track.t = t

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
            for j, z in enumerate(converted):
                d2 = _gate_distance(track, z)
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
            _position_update(track, converted[j])
            _range_rate_update(track, m, ego_velocity)
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

    def _new_track(
        self, t: float, m: Measurement, z: tuple[float, float, float, float, float], ego_v: tuple
    ) -> _Track:
        """A tentative track at the detection: position and its covariance R as measured,
        the radial velocity as measured (sd of the range rate), the tangential one unknown
        (``initial_speed_sd_mps``): P_vv = sd_r^2 u u^T + sd_t^2 n n^T."""
        ux, uy = math.cos(m.azimuth_rad), math.sin(m.azimuth_rad)
        radial = m.range_rate_mps + ux * ego_v[0] + uy * ego_v[1]
        sd_t2 = self.settings.initial_speed_sd_mps**2
        sd_r2 = max(m.range_rate_sd_mps, SD_FLOOR[2]) ** 2
        vxx = sd_r2 * ux * ux + sd_t2 * uy * uy
        vxy = sd_r2 * ux * uy - sd_t2 * uy * ux
        vyy = sd_r2 * uy * uy + sd_t2 * ux * ux
        P = [z[2], z[3], 0.0, 0.0, z[3], z[4], 0.0, 0.0, 0.0, 0.0, vxx, vxy, 0.0, 0.0, vxy, vyy]
        x = [z[0], z[1], radial * ux, radial * uy]
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
            TrackState(tr.tid, tr.x[0], tr.x[1], tr.x[2], tr.x[3], *tr.extent)
            for tr in self._tracks
            if tr.confirmed
        ]
