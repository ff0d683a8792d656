"""An automotive long-range radar: noisy, late, sometimes blind, tracked.

Per radar cycle (``cycle_s``) the radar measures every road user of which some part is
inside its range and field of view and not hidden behind a nearer road user (the exact box
geometry of :class:`~eoam_sumo.sensing.radar.Radar`; a target counts as hidden when the line of
sight to its nearest visible point and to each of its corners inside the cone passes
through a nearer box, and the first free one of those points is measured otherwise). Each
visible target is detected with probability ``detection_probability``; a detection is its
range, azimuth and range rate with Gaussian errors. The cycle's detections reach the
tracker ``latency_s`` later; the tracker (:mod:`eoam_sumo.sensing.tracker`) turns them into
confirmed tracks, and the report the EOAM reads is built from those tracks, as of the scan
they last saw (no latency compensation; the report's ``time_s`` is that scan's time, so a
user of it can carry its states on): the same :class:`~eoam_sumo.sensing.radar.RadarReport`
as the ideal radar, classified by the same rules on the tracked position and velocity.

Defaults (``AutomotiveRadarSettings``) from the data sheet of the Continental ARS 408-21
long-range radar (Continental Engineering Services, "ARS 408-21 Premium Long Range Radar
Sensor 77 GHz", ARS-408-21_EN_HS-1.pdf), far range: distance accuracy +-0.40 m, azimuth
accuracy +-0.1 deg, velocity resolution 0.37 km/h, field of view +-9 deg (the ideal radar's
18 deg); near range 0.20-70 m within +-45 deg. The data sheet itself could not be read here:
these figures were checked against a transcription of it (airou-lab/SynthCRAV,
utils/synthesizer.py, which cites that PDF) and, for the velocity accuracy (+-0.1 km/h) and
the range (up to 250 m), the nuScenes sensor table (Caesar et al. 2020, "nuScenes: A
multimodal dataset for autonomous driving", CVPR). The cycle time, about 72 ms, is
UNVERIFIED (nuScenes records this radar at 13 Hz, 77 ms). Accuracies are used as one
standard deviation (a conservative reading), the velocity resolution as the range-rate
noise (the accuracy is +-0.1 km/h); the near range's own accuracies (+-0.10 m; +-0.3 deg at
boresight to +-1 deg at +-45 deg) and its +-60 deg sector to 20 m are not modelled; the
range stays the ideal radar's setting (100 m, the paper's; the data sheet gives 250 m). The
data sheet gives no detection probability or output latency: 0.9 per cycle and one cycle
are assumptions.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np
from mypy_extensions import mypyc_attr

from eoam_sumo.errors import InputError
from eoam_sumo.sensing.radar import (
    EMPTY_REPORT,
    Detection,
    Radar,
    RadarReport,
    RadarSettings,
    RoadProjection,
    ray_entry_m,
    report_of,
)
from eoam_sumo.sensing.tracker import Measurement, Tracker, TrackerSettings
from eoam_sumo.world.bodies import Body

RADAR_MODELS = ("ideal", "automotive")
STREAM = 2  # random stream of the run seed (the friction estimator draws from stream 1)
_SEEN_EPS_M = 1e-6  # a blocker must start this much before the target's point [m]


@mypyc_attr(native_class=False)  # a Python dataclass: pickled, replaced
@dataclass(frozen=True)
class AutomotiveRadarSettings:
    """Noise, timing and detection of the automotive radar (sources: module docstring)."""

    range_sd_m: float = 0.40  # ARS 408-21 distance accuracy, far range (checked: SynthCRAV)
    azimuth_sd_deg: float = 0.1  # ARS 408-21 azimuth accuracy, far range (checked: SynthCRAV)
    range_rate_sd_mps: float = 0.37 / 3.6  # ARS 408-21 velocity resolution, far range
    # (checked: SynthCRAV); its velocity accuracy is +-0.1 km/h (nuScenes)
    cycle_s: float = 0.072  # ARS 408-21 cycle time, about 72 ms: UNVERIFIED (nuScenes: 13 Hz)
    latency_s: float = 0.072  # one cycle from scan to object list (assumed)
    detection_probability: float = 0.9  # per target and cycle (assumed)
    tracker: TrackerSettings = field(default_factory=TrackerSettings)

    def __post_init__(self) -> None:
        for name in ("range_sd_m", "azimuth_sd_deg", "range_rate_sd_mps", "latency_s"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise InputError(f"automotive radar {name} = {value!r} must be >= 0")
        if not (math.isfinite(self.cycle_s) and self.cycle_s > 0.0):
            raise InputError(f"automotive radar cycle_s = {self.cycle_s!r} must be > 0")
        if not 0.0 < self.detection_probability <= 1.0:
            raise InputError(
                "automotive radar detection_probability = "
                f"{self.detection_probability!r} must be in (0, 1]"
            )


def parse_radar_model(value) -> str:
    """``ideal`` or ``automotive``; InputError naming the value."""
    if isinstance(value, str) and value.strip().lower() in RADAR_MODELS:
        return value.strip().lower()
    raise InputError(f"radar_model {value!r} is not one of {', '.join(RADAR_MODELS)}")


class _Scan:
    """One cycle's measurements and where the ego was when it scanned."""

    __slots__ = ("deliver_at", "ego_s", "ego_velocity", "measurements", "origin", "t")

    def __init__(self, t, deliver_at, measurements, origin, ego_velocity, ego_s):
        self.t, self.deliver_at, self.measurements = t, deliver_at, measurements
        self.origin, self.ego_velocity, self.ego_s = origin, ego_velocity, ego_s


class AutomotiveRadar:
    """Drop-in for :class:`~eoam_sumo.sensing.radar.Radar`: ``scan`` once per step with the time."""

    def __init__(
        self,
        settings: RadarSettings | None = None,
        model: AutomotiveRadarSettings | None = None,
        seed: int = 0,
    ):
        self.settings = settings = settings or RadarSettings()
        self.model = model = model or AutomotiveRadarSettings()
        self._geometry = Radar(settings)
        self._rng = np.random.default_rng([seed, STREAM])
        self._tracker = Tracker(model.tracker)
        self._next_scan_s: float | None = None
        self._queue: deque[_Scan] = deque()
        self._report = EMPTY_REPORT

    def scan(
        self,
        ego_front_xy: tuple[float, float],
        ego_yaw_rad: float,
        ego_speed_mps: float,
        road_frame: RoadProjection,
        targets: Sequence[Body],
        lane_width_m: float,
        time_s: float | None = None,
    ) -> RadarReport:
        """The report the EOAM reads at ``time_s`` (scans when a cycle is due)."""
        if time_s is None:
            raise ValueError("the automotive radar needs the time of each scan (time_s)")
        if self._next_scan_s is None:
            self._next_scan_s = time_s
        if time_s + 1e-9 >= self._next_scan_s:
            self._next_scan_s += self.model.cycle_s * max(
                1, math.floor((time_s + 1e-9 - self._next_scan_s) / self.model.cycle_s) + 1
            )
            self._queue.append(
                self._measure(time_s, ego_front_xy, ego_yaw_rad, ego_speed_mps, road_frame, targets)
            )
        delivered = None
        while self._queue and self._queue[0].deliver_at <= time_s + 1e-9:
            delivered = self._queue.popleft()
            self._tracker.update(
                delivered.t, delivered.measurements, delivered.origin, delivered.ego_velocity
            )
        if delivered is not None:
            self._report = self._build_report(delivered, road_frame, lane_width_m)
        return self._report

    # ----------------------------------------------------------------------------- sensing
    def _measure(self, t, front, yaw, speed, road_frame, targets) -> _Scan:
        ox, oy = front
        bx, by = math.cos(yaw), math.sin(yaw)
        visible = self._visible(ox, oy, yaw, bx, by, targets)
        model, rng = self.model, self._rng
        az_sd = math.radians(model.azimuth_sd_deg)
        measurements = []
        for tgt, r, px, py in visible:
            draws = rng.random(), rng.standard_normal(3)  # four draws per visible target
            if draws[0] >= model.detection_probability:
                continue
            los = math.atan2(py - oy, px - ox)
            ux, uy = math.cos(los), math.sin(los)
            box = tgt.box
            rr = (tgt.speed_mps * box.cos_yaw - speed * bx) * ux + (
                tgt.speed_mps * box.sin_yaw - speed * by
            ) * uy
            e = draws[1]
            measurements.append(
                Measurement(
                    max(r + model.range_sd_m * e[0], 0.0),
                    los + az_sd * e[1],
                    rr + model.range_rate_sd_mps * e[2],
                    model.range_sd_m,
                    az_sd,
                    model.range_rate_sd_mps,
                    box.x_m - px,
                    box.y_m - py,
                    tgt.length_m,
                    tgt.width_m,
                )
            )
        ego_s = road_frame.project(ox, oy)[0]
        return _Scan(
            t, t + model.latency_s, measurements, (ox, oy), (speed * bx, speed * by), ego_s
        )

    def _visible(self, ox, oy, yaw, bx, by, targets) -> list:
        """(target, range, x, y) of each target with a part in a beam and a free line of
        sight to it, nearest first."""
        geo = self._geometry
        reach_m = self.settings.range_m
        inside = []
        for tgt in targets:
            box = tgt.box
            if math.hypot(box.x_m - ox, box.y_m - oy) > reach_m + box.radius_m:
                continue
            r, px, py = geo.seen_point(ox, oy, yaw, bx, by, box)
            if r < math.inf:
                inside.append((r, tgt, px, py))
        inside.sort(key=lambda item: item[0])
        seen = []
        for k, (r, tgt, px, py) in enumerate(inside):
            nearer = [item[1].box for item in inside[:k]]
            candidates = [
                (r, px, py),
                *sorted(
                    (math.hypot(cx - ox, cy - oy), cx, cy)
                    for cx, cy in tgt.box.corners()
                    if geo.covers(ox, oy, yaw, cx, cy)
                ),
            ]
            for cr, cx, cy in candidates:
                if not _blocked(nearer, ox, oy, cx, cy, cr):
                    seen.append((tgt, cr, cx, cy))
                    break
        return seen

    # ----------------------------------------------------------------------------- report
    def _build_report(
        self, scan: _Scan, road_frame: RoadProjection, lane_width_m: float
    ) -> RadarReport:
        ox, oy = scan.origin
        evx, evy = scan.ego_velocity
        speed = math.hypot(evx, evy)
        bx, by = (evx / speed, evy / speed) if speed > 1e-9 else (1.0, 0.0)
        band_m = 0.5 * lane_width_m + self.settings.lane_margin_m
        detections = []
        for tr in self._tracker.confirmed():
            rx, ry = tr.x_m - ox, tr.y_m - oy
            rng = math.hypot(rx, ry)
            lx, ly = (rx / rng, ry / rng) if rng > 1e-9 else (bx, by)
            range_rate = (tr.vx_mps - evx) * lx + (tr.vy_mps - evy) * ly
            bearing = math.atan2(bx * ly - by * lx, bx * lx + by * ly)
            s, d, road_yaw = road_frame.project(tr.x_m + tr.centre_dx_m, tr.y_m + tr.centre_dy_m)
            road_speed = tr.vx_mps * math.cos(road_yaw) + tr.vy_mps * math.sin(road_yaw)
            # the lateral velocity of a track far ahead is poorly observed: stopped or not
            # is judged on the speed along the road
            ahead = s > scan.ego_s
            category = self._geometry.classify(
                ahead, d, abs(road_speed), road_speed, band_m, lane_width_m
            )
            detections.append(
                Detection(
                    tr.track_id,
                    rng,
                    range_rate,
                    bearing,
                    s,
                    d,
                    road_speed,
                    category,
                    tr.length_m,
                    tr.width_m,
                    self._geometry.head_on(category, ahead, d, band_m),
                )
            )
        return report_of(detections)._replace(time_s=scan.t)


def _blocked(nearer, ox, oy, px, py, r) -> bool:
    """The segment from the radar to (px, py), of length r, enters one of the boxes."""
    if r <= 1e-9:
        return False
    ux, uy = (px - ox) / r, (py - oy) / r
    return any(ray_entry_m(box, ox, oy, ux, uy) < r - _SEEN_EPS_M for box in nearer)


#: The ARS 408-21's near-range beam: 0.20-70 m within +-45 deg (data sheet, near range;
#: checked: SynthCRAV); its +-60 deg sector out to 20 m is not modelled.
NEAR_RANGE_M = 70.0
NEAR_FOV_DEG = 90.0


def make_radar(model: str, settings: RadarSettings, seed: int = 0):
    """The radar of a run: :class:`Radar` (ideal) or :class:`AutomotiveRadar` (with the data
    sheet's near-range beam unless ``settings`` has one)."""
    model = parse_radar_model(model)
    if model == "ideal":
        return Radar(settings)
    if settings.near_range_m == 0.0:
        settings = replace(
            settings, near_range_m=min(NEAR_RANGE_M, settings.range_m), near_fov_deg=NEAR_FOV_DEG
        )
    return AutomotiveRadar(settings, seed=seed)
