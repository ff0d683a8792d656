"""Forward radar model on road users: detection, range, range rate, classification.

The radar sits at the centre of the ego's front bumper and looks along the ego's heading
(paper sec. 10.1, Figures 16 and 18: a long-range radar with a narrow field of view that
does not see the ARO 120 m ahead at the start). SUMO only supplies the candidate list; all
geometry is here, on ground-truth boxes (no ids are used).

Detection: a target is seen when some part of its box lies within ``range_m`` of the radar
and inside the field of view. This is computed exactly as the distance from the radar to the
part of the box inside the field-of-view cone: the box's nearest point when that lies in the
cone, otherwise the first crossing of the box by one of the two edge rays of the cone (this
also covers the corners and the nearest point of the rear face). That distance is the
reported range. Occlusion is ignored: a target hidden behind another is still seen. An
optional second, wide near-range beam (``near_range_m``, ``near_fov_deg``; off by default, as
the paper's radar has one beam) covers what is close beside the boresight. An in-path target
that leaves the beams within range is kept as a predicted object (``RadarReport.coasted``,
:mod:`eoam_sumo.sensing.coasting`).

Measurements per detection: range to the nearest visible point, range rate (relative velocity
projected on the line of sight to that point, negative when closing; ego velocity taken
along its heading), bearing, and the road-frame station and lateral offset of the target's
centre from the road frame of the ego's ORIGINAL lane (``project(x, y) -> (s, d, road_yaw)``,
d positive to the left; e.g. ``eoam_sumo.sim.roadframe.RoadFrame``). "In path" is therefore
relative to the lane the ego started in, also while it is in the other lane or returning: the
ARO stays the in-path object the DMM tracks until it leaves the field of view (paper sec. 6.1).

Classification (lane band half-width = lane_width_m / 2 + lane_margin_m, on the centre's d;
road speed = target speed times the cosine of its heading relative to the road; the next lane's
band runs from the lane band's edge one next-lane width to the left: ``next_lane_width_m``, the
width of the lane a lane change would take, or the ego lane's when not given):

* ``oncoming``: road speed below -oncoming_speed_mps and the centre in the lane band or in
  the next lane's band: in the ego lane (a wrong-way driver counts) or in the lane a lane
  change would take; in the next lane's band also any road user moving towards the ego at
  stationary_speed_mps or more (:func:`~eoam_sumo.eoam_messages.next_lane_motion`: a van
  creeping at 1.5 m/s). A road user moving against the road further left (the other
  carriageway of a divided road, a jogger on the far pavement) is ``other``: it is not in the
  way of the lane change;
* ``in_path``: centre ahead of the ego's front bumper along the road, inside the lane band,
  and not oncoming (road speed above -oncoming_speed_mps): stopped, moving with the road, or
  slowly towards the ego (a person walking towards it in its lane, a car backing up); also a
  car ahead in a neighbouring lane cutting in (``cutting_in``: moving towards the ego's lane,
  past ``CUT_IN_WANDER_M`` from its lane's centre for ``CUT_IN_PERCEPTION_S``);
* ``in_next_lane``: ahead, the centre in the next lane's band and standing along the road
  (road speed below stationary_speed_mps either way; a person walking across the lane
  counts, cross traffic faster than ``ONCOMING_SPEED_MPS`` does not): a standing road user
  in the lane an evasive lane change would take. So in the next lane every road user is
  oncoming, standing, or moving the ego's way (the paper policy's commit check judges those);
* ``stationary_side``: speed below stationary_speed_mps and the centre outside the lane band
  otherwise (parked cars; never in path, never oncoming);
* ``other``: everything else (e.g. traffic in another lane moving with the ego).

An oncoming target whose centre is ahead inside the lane band is also the in-path obstacle
(``Detection.head_on``; Euro NCAP's CCFhos, a car driving straight at the ego in its lane):
the nearest in-path target is the nearest one classed ``in_path`` or head-on, so the EOAM
sees its range and range rate (the closing speed, ego + target) while the ``oncoming`` flag
stays raised, and with it the paper's rule for oncoming traffic, braking in the lane (mode 3,
sec. 3.2) rather than steering into the next lane.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from operator import attrgetter
from typing import NamedTuple

from mypy_extensions import mypyc_attr

from eoam_sumo.eoam_messages import ONCOMING, STANDING, next_lane_motion
from eoam_sumo.sensing.coasting import Coaster
from eoam_sumo.world.bodies import Body
from eoam_sumo.world.geometry import OrientedBox, nearest_point, slab_entry
from eoam_sumo.world.lanes import (
    CROSSING_ANGLE_RAD,
    LANE_MARGIN_M,
    ONCOMING_SPEED_MPS,
    STATIONARY_SPEED_MPS,
    RoadProjection,
    body_band_m,
    lane_band_m,
)

CATEGORIES = ("in_path", "oncoming", "in_next_lane", "stationary_side", "other")


@mypyc_attr(native_class=False)  # a Python dataclass: pickled, replaced
@dataclass(frozen=True)
class RadarSettings:
    """Radar coverage and the classification thresholds (reasons at the constants of
    :mod:`eoam_sumo.world.lanes`)."""

    range_m: float = 100.0  # long-range radar; the ARO at 120 m is outside at start (Fig. 18)
    fov_deg: float = 18.0  # full horizontal field of view, narrow forward beam
    stationary_speed_mps: float = STATIONARY_SPEED_MPS
    oncoming_speed_mps: float = ONCOMING_SPEED_MPS
    lane_margin_m: float = LANE_MARGIN_M
    near_range_m: float = 0.0  # a second, wide near-range beam this long (0: none) [m]
    near_fov_deg: float = 90.0  # its full horizontal field of view [deg]
    # the width of the lane a lane change would take, left of the ego's (0: the ego lane's):
    # the session's, given per run (a wider target lane's far side is in the next lane) [m]
    next_lane_width_m: float = 0.0

    def __post_init__(self) -> None:
        for name in (
            "range_m",
            "fov_deg",
            "stationary_speed_mps",
            "oncoming_speed_mps",
            "lane_margin_m",
            "near_range_m",
            "near_fov_deg",
            "next_lane_width_m",
        ):
            v = getattr(self, name)
            if not math.isfinite(v) or v < 0.0:
                raise ValueError(f"RadarSettings.{name}={v!r} must be finite and >= 0")
        if self.range_m <= 0.0:
            raise ValueError(f"RadarSettings.range_m={self.range_m} must be > 0")
        if not 0.0 < self.fov_deg < 180.0:
            raise ValueError(f"RadarSettings.fov_deg={self.fov_deg} must be in (0, 180)")
        if self.near_range_m > self.range_m or not 0.0 < self.near_fov_deg < 180.0:
            raise ValueError(
                f"RadarSettings.near_range_m={self.near_range_m} must be <= "
                f"range_m and near_fov_deg={self.near_fov_deg} in (0, 180)"
            )
        if self.oncoming_speed_mps < self.stationary_speed_mps:
            raise ValueError(
                f"RadarSettings.oncoming_speed_mps={self.oncoming_speed_mps} must be >= "
                f"stationary_speed_mps={self.stationary_speed_mps}"
            )


class Detection(NamedTuple):
    """One detected target: measurements, road-frame position and class (a named tuple: built
    at every scan)."""

    target_index: int  # position in the scanned target list (for logging only)
    range_m: float
    range_rate_mps: float  # negative when closing
    bearing_rad: float  # of the measured point from the boresight, left positive
    s_m: float  # road-frame station of the target's centre
    d_m: float  # road-frame lateral offset of the target's centre, left positive
    road_speed_mps: float  # target speed along the road direction, negative against it
    category: str
    length_m: float  # object size, as a tracking sensor reports it
    width_m: float
    head_on: bool = False  # oncoming, centre ahead in the lane band: in the path as well


class RadarReport(NamedTuple):
    """What the EOAM logic uses (nearest in-path target, oncoming flag) plus all detections."""

    in_path_range_m: float | None
    in_path_range_rate_mps: float | None
    oncoming_detected: bool
    detections: tuple[Detection, ...]  # sorted by range
    in_path_index: int | None = None  # target-list index of the nearest in-path target
    in_path: Detection | None = None  # the nearest in-path detection itself
    next_lane_range_m: float | None = None  # nearest standing object in the next lane
    coasted: Detection | None = None  # an in-path object out of view, predicted (not measured)
    time_s: float | None = None  # when its detections' states held (None: at the scan)


_range_of = attrgetter("range_m")
#: A car in the next lane is cutting in once its centre has moved more than this from that
#: lane's centre towards the ego's lane, still moving towards it, and ``CUT_IN_PERCEPTION_S``
#: has passed since: the lateral wandering threshold (0.375 m) and the risk perception time
#: (0.4 s) of the competent and careful driver model of UN Regulation No. 157 (ALKS), Annex 4
#: Appendix 3, as implemented by esmini's ALKS reference driver
#: (EnvironmentSimulator/Modules/Controllers/ControllerALKS_R157SM.hpp, ReferenceDriver:
#: ``wandering_threshold_`` 0.375, ``perception_time_`` 0.4) after the JRC's ec-jrc/JRC-FSM.
#: The regulation's own text was not in the searchable corpora.
CUT_IN_WANDER_M = 0.375
CUT_IN_PERCEPTION_S = 0.4
CUT_IN_LATERAL_MPS = 0.1  # the lateral speed towards the ego's lane that counts as moving [m/s]

EMPTY_REPORT = RadarReport(None, None, False, ())  # immutable: one for every empty scan


def ray_entry_m(box: OrientedBox, ox: float, oy: float, ux: float, uy: float) -> float:
    """Distance along the ray (origin o, unit direction u) to where it enters the box, or inf."""
    bx, by, _, _, _, c, s, hl, hw, _ = box  # see ``_BoxFields``
    dx, dy = ox - bx, oy - by
    lox, loy = c * dx + s * dy, -s * dx + c * dy  # ``to_local``
    lux = c * ux + s * uy
    luy = -s * ux + c * uy
    return slab_entry(((lox, lux, hl), (loy, luy, hw)), math.inf)


def report_of(detections: list[Detection]) -> RadarReport:
    """The report of a scan's detections: sorted by range, the nearest in-path one (classed
    ``in_path`` or head-on), the oncoming flag and the nearest standing object in the next
    lane."""
    if not detections:
        return EMPTY_REPORT
    detections.sort(key=_range_of)
    in_path, oncoming, next_lane = None, False, None
    for det in detections:
        category = det.category
        if in_path is None and (category == "in_path" or det.head_on):
            in_path = det
        if category == "oncoming":
            oncoming = True
        elif category == "in_next_lane" and next_lane is None:
            next_lane = det.range_m
    if in_path is None:
        return RadarReport(None, None, oncoming, tuple(detections), next_lane_range_m=next_lane)
    return RadarReport(
        in_path.range_m,
        in_path.range_rate_mps,
        oncoming,
        tuple(detections),
        in_path.target_index,
        in_path,
        next_lane,
    )


class _EgoView(NamedTuple):
    """The ego as one scan sees it: the radar's position and heading (with its cosine and
    sine), the ego's velocity, its station and the lane band of its original lane."""

    x_m: float
    y_m: float
    yaw_rad: float
    cos_yaw: float
    sin_yaw: float
    vx_mps: float
    vy_mps: float
    s_m: float
    band_m: float
    lane_width_m: float


class Radar:
    """Radar at the ego's front bumper; ``scan`` turns ground truth into a ``RadarReport``."""

    def __init__(self, settings: RadarSettings = RadarSettings()):
        self.settings = settings
        self._half_fov_rad = math.radians(0.5 * settings.fov_deg)
        self._cos_half_fov = math.cos(self._half_fov_rad)
        self._sin_half_fov = math.sin(self._half_fov_rad)
        self._near = None  # the near-range beam, as a radar of its own
        self._coaster = Coaster()
        if settings.near_range_m > 0.0:
            self._near = Radar(
                replace(
                    settings,
                    range_m=settings.near_range_m,
                    fov_deg=settings.near_fov_deg,
                    near_range_m=0.0,
                )
            )

    def seen_point(
        self, ox: float, oy: float, yaw_rad: float, cos_yaw: float, sin_yaw: float, box: OrientedBox
    ) -> tuple[float, float, float]:
        """(distance, x, y) of the nearest point of ``box`` the radar covers (the far beam
        within ``range_m``, the near beam within ``near_range_m``); distance inf if none."""
        rng, px, py = self.visible_point(ox, oy, yaw_rad, cos_yaw, sin_yaw, box)
        if rng > self.settings.range_m:
            rng = math.inf
        if self._near is not None:
            near = self._near.seen_point(ox, oy, yaw_rad, cos_yaw, sin_yaw, box)
            if near[0] < rng:
                return near
        return rng, px, py

    def covers(self, ox: float, oy: float, yaw_rad: float, px: float, py: float) -> bool:
        """Whether the point (px, py) lies in one of the beams."""
        r = math.hypot(px - ox, py - oy)
        off = abs(math.remainder(math.atan2(py - oy, px - ox) - yaw_rad, math.tau))
        if r <= self.settings.range_m and off <= self._half_fov_rad:
            return True
        return self._near is not None and self._near.covers(ox, oy, yaw_rad, px, py)

    def visible_range_m(
        self, origin_xy: tuple[float, float], yaw_rad: float, box: OrientedBox
    ) -> float:
        """Distance from the radar to the part of ``box`` inside the field-of-view cone (inf if
        none); the box is detected when this is within ``range_m``."""
        return self.visible_point(
            origin_xy[0], origin_xy[1], yaw_rad, math.cos(yaw_rad), math.sin(yaw_rad), box
        )[0]

    def visible_point(
        self,
        ox: float,
        oy: float,
        yaw_rad: float,
        cos_yaw: float,
        sin_yaw: float,
        box: OrientedBox,
    ) -> tuple[float, float, float]:
        """(distance, x, y) of the point of ``box`` inside the cone nearest to the radar."""
        px, py = nearest_point(box, ox, oy)
        rx, ry = px - ox, py - oy
        r = math.hypot(rx, ry)
        if r <= 1e-9 or rx * cos_yaw + ry * sin_yaw >= r * self._cos_half_fov - 1e-12:
            return r, px, py
        best = (math.inf, ox, oy)
        for side in (1.0, -1.0):
            ang = yaw_rad + side * self._half_fov_rad
            ux, uy = math.cos(ang), math.sin(ang)
            t = ray_entry_m(box, ox, oy, ux, uy)
            if t < best[0]:
                best = (t, ox + t * ux, oy + t * uy)
        return best

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
        """Detect and classify ``targets`` seen from the ego's front bumper (rules: module
        doc); ``time_s`` is for radars with a cycle (the ideal one sees at every call)."""
        if not lane_width_m > 0.0:
            raise ValueError(f"lane_width_m={lane_width_m} must be > 0")
        ox, oy = ego_front_xy
        bx, by = math.cos(ego_yaw_rad), math.sin(ego_yaw_rad)
        ego = _EgoView(
            ox,
            oy,
            ego_yaw_rad,
            bx,
            by,
            ego_speed_mps * bx,
            ego_speed_mps * by,
            road_frame.project(ox, oy)[0],
            lane_band_m(lane_width_m, self.settings.lane_margin_m),
            lane_width_m,
        )
        detections = []
        for index, tgt in enumerate(targets):
            seen = self._seen_by_beams(ego, tgt.box)
            if seen is not None:
                detections.append(self._detection(ego, index, tgt, seen, road_frame))
        return self._coasting(ego, report_of(detections), targets, road_frame, time_s)

    def _seen_by_beams(self, ego: _EgoView, box: OrientedBox) -> tuple[float, float, float] | None:
        """(distance, x, y) of the nearest point of ``box`` in the beams, or None: the
        bounding circle out of range or (one beam) wholly outside the cone first."""
        range_m = self.settings.range_m
        ox, oy, bx, by = ego.x_m, ego.y_m, ego.cos_yaw, ego.sin_yaw
        box_x, box_y, _, _, _, _, _, _, _, radius_m = box  # see ``_BoxFields``
        dx, dy = box_x - ox, box_y - oy
        reach = range_m + radius_m
        if dx * dx + dy * dy > reach * reach:
            return None
        if self._near is not None:
            seen = self.seen_point(ox, oy, ego.yaw_rad, bx, by, box)
            return None if seen[0] == math.inf else seen
        along, across = dx * bx + dy * by, abs(dy * bx - dx * by)
        if along * self._sin_half_fov - across * self._cos_half_fov < -radius_m:
            return None
        seen = self.visible_point(ox, oy, ego.yaw_rad, bx, by, box)
        return None if seen[0] > range_m else seen

    def _detection(
        self,
        ego: _EgoView,
        index: int,
        tgt: Body,
        seen: tuple[float, float, float],
        road_frame: RoadProjection,
    ) -> Detection:
        """The measurements and class of target ``index`` seen at (distance, x, y) ``seen``."""
        _, _, _, _, _, speed_mps, length_m, width_m, _, box = tgt  # see ``_BodyFields``
        box_x, box_y, box_yaw, _, _, box_c, box_s, _, _, _ = box
        ox, oy, bx, by = ego.x_m, ego.y_m, ego.cos_yaw, ego.sin_yaw
        rng, px, py = seen
        if rng > 1e-9:
            lx, ly = (px - ox) / rng, (py - oy) / rng
        else:
            dx, dy = box_x - ox, box_y - oy
            norm = math.hypot(dx, dy)
            lx, ly = (dx / norm, dy / norm) if norm > 1e-9 else (bx, by)
        tvx, tvy = speed_mps * box_c, speed_mps * box_s
        range_rate = (tvx - ego.vx_mps) * lx + (tvy - ego.vy_mps) * ly
        bearing = math.atan2(bx * ly - by * lx, bx * lx + by * ly)
        s, d, road_yaw = road_frame.project(box_x, box_y)
        road_speed = speed_mps * math.cos(box_yaw - road_yaw)
        ahead = s > ego.s_m
        lateral = speed_mps * math.sin(box_yaw - road_yaw)
        band = body_band_m(ego.band_m, width_m)
        category = self.classify(ahead, d, speed_mps, road_speed, band, ego.lane_width_m, lateral)
        return Detection(
            index,
            rng,
            range_rate,
            bearing,
            s,
            d,
            road_speed,
            category,
            length_m,
            width_m,
            self.head_on(category, ahead, d, band),
        )

    def _coasting(
        self,
        ego: _EgoView,
        report: RadarReport,
        targets: Sequence[Body],
        road_frame: RoadProjection,
        time_s: float | None,
    ) -> RadarReport:
        """``report`` with the in-path object coasted when it left the beams within range
        (:mod:`eoam_sumo.sensing.coasting`); the coaster is asked only when something may be or
        is coasted, else it just remembers the in-path object."""
        coaster = self._coaster
        if coaster.coasted is None:  # nothing coasted: only remember the in-path object
            det, last = report.in_path, coaster.last
            if det is not None:
                body = targets[det.target_index]
                if last is None or last.vid == body.vid:
                    coaster.last, coaster.last_t = body, time_s
                    return report
            elif last is None:
                return report
        seen = None if report.in_path is None else targets[report.in_path.target_index]
        coasted = coaster.coast(
            self,
            self.settings.range_m,
            seen,
            [targets[det.target_index] for det in report.detections],
            ego.x_m,
            ego.y_m,
            ego.yaw_rad,
            ego.vx_mps,
            ego.vy_mps,
            ego.s_m,
            road_frame.project,
            ego.band_m,
            ego.lane_width_m,
            time_s,
        )
        return report if coasted is None else report._replace(coasted=Detection(*coasted))

    def classify(
        self,
        ahead: bool,
        d_m: float,
        speed_mps: float,
        road_speed_mps: float,
        band_m: float,
        lane_width_m: float,
        lateral_mps: float = 0.0,
    ) -> str:
        """The class of a target (rules: module doc); ``lateral_mps`` its speed across the
        road (positive to the left): a car ahead in a neighbouring lane moving towards the
        ego's lane beyond ``CUT_IN_WANDER_M`` of its lane centre for ``CUT_IN_PERCEPTION_S``
        is in the path (a cut-in, :func:`cutting_in`)."""
        st = self.settings
        next_edge_m = band_m + (st.next_lane_width_m or lane_width_m)
        if road_speed_mps < -st.oncoming_speed_mps and -band_m < d_m < next_edge_m:
            return "oncoming"
        if abs(d_m) < band_m:
            if ahead:  # not oncoming (tested above)
                return "in_path"
            return "other"
        if ahead and cutting_in(d_m, lateral_mps, lane_width_m, band_m):
            return "in_path"
        if band_m <= d_m < next_edge_m and not crossing(speed_mps, road_speed_mps):
            motion = next_lane_motion(road_speed_mps, st.stationary_speed_mps)
            if motion == ONCOMING:
                return "oncoming"
            if motion == STANDING:
                return "in_next_lane" if ahead else "stationary_side"
            return "other"
        if abs(speed_mps) < st.stationary_speed_mps:
            return "stationary_side"
        return "other"

    def head_on(self, category: str, ahead: bool, d_m: float, band_m: float) -> bool:
        """Whether a target of ``category`` is oncoming with its centre ahead inside the lane
        band: a wrong-way road user in the ego's lane, the in-path obstacle as well."""
        return category == "oncoming" and ahead and abs(d_m) < band_m


def crossing(speed_mps: float, road_speed_mps: float) -> bool:
    """Cross traffic: faster than ``ONCOMING_SPEED_MPS``, heading more than
    ``CROSSING_ANGLE_RAD`` off the road (as ``world.lanes.crosses_lane``, from the speeds)."""
    speed = abs(speed_mps)
    return speed > ONCOMING_SPEED_MPS and abs(road_speed_mps) < speed * math.cos(CROSSING_ANGLE_RAD)


def cutting_in(d_m: float, lateral_mps: float, lane_width_m: float, band_m: float) -> bool:
    """A road user centred ``d_m`` from the ego's lane centre, in a neighbouring lane (outside
    the lane band, within one lane width beyond it), moving towards the ego's lane, that
    crossed ``CUT_IN_WANDER_M`` from that lane's centre at least ``CUT_IN_PERCEPTION_S`` ago
    at its present lateral speed (R157's competent and careful driver: the risk is perceived
    that long after the wandering threshold is crossed)."""
    if not band_m <= abs(d_m) < band_m + lane_width_m:
        return False
    towards = -math.copysign(1.0, d_m) * lateral_mps
    beyond_m = lane_width_m - abs(d_m) - CUT_IN_WANDER_M
    return towards > CUT_IN_LATERAL_MPS and beyond_m >= CUT_IN_PERCEPTION_S * towards
