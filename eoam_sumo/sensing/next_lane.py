"""What the ego knows of the next lane: sensor coverage, road users in it, V2X fused in.

The next lane is the one left of the ego's original lane, between d = w/2 and 3 w/2 in that
lane's road frame (w the lane width). Three sensors look at it, all on the ego's body:

* the forward radar (``sim.radar``): its range and field of view from the front bumper, with
  the shadow of every other road user it reports (a point whose line of sight crosses the box
  of a reported object, placed along the road at its station and offset, is hidden);
* two left corner radars (front-left and rear-left corners), each looking ``boresight_deg``
  outward from the ego's axis (forward and backward), with the range and field of view of a
  24 GHz lane-change-assist radar: Autoliv SRR "NB" sensor, user manual filed with the FCC,
  LCA mode: search range 4-80 m, azimuth -40 to +40 deg at the -6 dB points;
* V2X (``sensing.v2x``): objects of the equipped road users; when every road user is equipped
  the whole reception range counts as seen, less the distance the fastest road user covers
  while it may go unheard (``V2XSettings.blind_time_s``).

The strip of lane beside the ego's body, between the corner radars' fields, counts as seen: a
road user there came through a seen part (a tracker follows it), and is reported. Coverage is
measured on three lines along the lane (0.25 m inside each marker and its centre), at points
every ``COVERAGE_STEP_M`` placed on the road (curves included) from ``BESIDE_M`` ahead of the
front bumper: the covered length ahead ends at the last point before the first one that no
sensor sees on any line. It is worked out only when the policy reads it (at a commit).

Road users in the lane are those whose box overlaps it by at least ``MIN_OVERLAP_M``, from the
forward radar's detections, the corner radars' and V2X, one object per road user (a V2X object
within ``FUSION_GATE_M`` of a radar object is the same road user), except the in-path obstacle
the EOAM is avoiding. Their speed or direction does not matter.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from mypy_extensions import mypyc_attr

from eoam_sumo.eoam_messages import NextLaneView
from eoam_sumo.sensing.v2x import V2XObject, V2XReceiver, V2XSettings
from eoam_sumo.world.bodies import Body
from eoam_sumo.world.geometry import OrientedBox, nearest_point, slab_entry

MIN_OVERLAP_M = 0.1  # a road user reaching this far into the lane is in it [m]
FUSION_GATE_M = 3.0  # radar and V2X objects closer than this (centre, plus half lengths) [m]
LINE_INSET_M = 0.25  # coverage lines: this far inside each lane marker [m]
STANDING_CACHE = 4096  # road-frame positions of standing road users kept at most
BESIDE_M = 2.0  # a road user within this of the ego's body along the road is beside it [m]
#: A sensor: position (x, y), look direction, half field of view [rad], range [m].
Sensor = tuple[float, float, float, float, float]
COVERAGE_STEP_M = 1.0  # spacing of the points at which coverage is tested [m]
ACCEL_BASELINE_S = 0.5  # a road user's acceleration: its speed change over this long [s]


@mypyc_attr(native_class=False)  # a Python dataclass: pickled, replaced
@dataclass(frozen=True)
class CornerRadarSettings:
    """Left corner radars (module doc: Autoliv 24 GHz SRR, LCA mode)."""

    range_m: float = 80.0
    fov_deg: float = 80.0  # full azimuth field (-40 to +40 deg)
    boresight_deg: float = 40.0  # outward from the ego's axis, forward (front) and back (rear)

    def __post_init__(self) -> None:
        if not (
            self.range_m >= 0.0 and 0.0 < self.fov_deg < 180.0 and 0.0 <= self.boresight_deg <= 90.0
        ):
            raise ValueError(f"corner radar settings out of range: {self}")


def sees(
    ox: float, oy: float, look_rad: float, half_fov_rad: float, range_m: float, px: float, py: float
) -> bool:
    """A sensor at (ox, oy) looking along ``look_rad`` sees the point (px, py): within its
    range and field of view."""
    dx, dy = px - ox, py - oy
    if dx * dx + dy * dy > range_m * range_m:
        return False
    return abs(math.remainder(math.atan2(dy, dx) - look_rad, math.tau)) <= half_fov_rad


def hides(box, ox: float, oy: float, px: float, py: float) -> bool:
    """The segment from (ox, oy) to (px, py) crosses ``box`` (an ``OrientedBox``) before its
    end: the box hides the point from a sensor at (ox, oy) (slab test in the box's frame)."""
    ax, ay = box.to_local(ox, oy)
    bx, by = box.to_local(px, py)
    slabs = ((ax, bx - ax, box.half_length_m), (ay, by - ay, box.half_width_m))
    return slab_entry(slabs, 1.0) < 1.0 - 1e-9


class NextLaneSensing:
    """Builds the :class:`NextLaneView` of each step from the sensors (module doc)."""

    def __init__(
        self,
        *,
        opposing: bool,
        speed_limit_mps: float,
        lane_width_m: float,
        radar_range_m: float,
        radar_fov_deg: float,
        ego_length_m: float,
        ego_width_m: float,
        v2x: V2XSettings | None = None,
        corner: CornerRadarSettings | None = None,
        fastest_mps: float | None = None,
        side: int = 1,
        target_width_m: float | None = None,
    ):
        self.opposing = opposing
        self.side = 1 if side >= 0 else -1  # +1: the lane left of the ego's, -1: right of it
        self.speed_limit_mps = speed_limit_mps
        self.lane_width_m = lane_width_m
        self.radar_range_m = radar_range_m
        self._radar_half_fov = math.radians(0.5 * radar_fov_deg)
        self.ego_length_m, self.ego_width_m = ego_length_m, ego_width_m
        v2x = v2x or V2XSettings()
        self.corner = corner or CornerRadarSettings()
        # the corner radars' half field of view and boresight (toward the lane's side) [rad]
        self._corner_half_fov = math.radians(0.5 * self.corner.fov_deg)
        self._corner_bore = math.radians(self.corner.boresight_deg) * self.side
        self.v2x = V2XReceiver(v2x) if v2x.enabled else None
        fastest = speed_limit_mps if fastest_mps is None else fastest_mps
        self._v2x_free_m = v2x.range_m - fastest * v2x.blind_time_s() if v2x.covers_all else 0.0
        w = lane_width_m
        wt = self.target_width_m = w if target_width_m is None else target_width_m
        inner, outer = 0.5 * w, (1.5 * w if wt == w else 0.5 * w + wt)
        centre = w if wt == w else 0.5 * (inner + outer)
        sgn = self.side
        # the lane's band in the ego's road frame (d_lo, d_hi) and its three coverage lines
        self.band_m = (inner, outer) if sgn > 0 else (-outer, -inner)
        self.lines_m = tuple(
            sgn * line for line in (inner + LINE_INSET_M, centre, outer - LINE_INSET_M)
        )
        self._standing: dict[tuple[float, float], tuple[float, float, float]] = {}
        # the road users in the lane at the last steps: (time, station, speed, the speed
        # history (time, speed) over the last ACCEL_BASELINE_S)
        self._tracks: list[tuple[float, float, float, list[tuple[float, float]]]] = []

    @property
    def reach_m(self) -> float:
        """How far from the ego the road users it may sense can be (V2X or a corner radar)."""
        return max(
            self.v2x.settings.range_m if self.v2x is not None else 0.0,
            self.corner.range_m + self.ego_length_m,
        )

    def update(
        self,
        time_s: float,
        front_xy: tuple[float, float],
        yaw_rad: float,
        road,
        report,
        bodies: Sequence,
    ) -> NextLaneView:
        """The view at ``time_s``: ``report`` the forward radar's (``sim.radar.RadarReport``),
        ``bodies`` the ground truth of the road users around (for the corner radars and V2X),
        ``road`` the original lane's frame (``project(x, y) -> (s, d, road_yaw)``)."""
        s_f = road.project(*front_xy)[0]
        lane_lo, lane_hi = self.band_m
        in_path = report.in_path
        objects, shadows = self._radar_objects(report, lane_lo, lane_hi)
        objects += self._corner_objects(
            front_xy, s_f, yaw_rad, road, bodies, lane_lo, lane_hi, objects, in_path
        )
        if self.v2x is not None:
            self.v2x.update(time_s, front_xy, bodies)
            received = self.v2x.objects(time_s)
            self._add_v2x_objects(received, road, lane_lo, lane_hi, objects, in_path)
        accel = self._accelerations(time_s, objects)
        ahead, behind = self._nearest(objects, accel, s_f)

        def coverage() -> float:
            return self._coverage(road, s_f, front_xy, yaw_rad, shadows)

        return NextLaneView(
            self.opposing,
            self.speed_limit_mps,
            coverage=coverage,
            nearest_ahead_m=ahead[0][0] if ahead else None,
            nearest_ahead_speed_mps=ahead[0][1] if ahead else None,
            nearest_behind_m=None if behind is None else behind[0],
            nearest_behind_speed_mps=None if behind is None else behind[1],
            ahead=tuple([(gap, v) for gap, v, _a in ahead]),
            accel_ahead_mps2=tuple([a for _gap, _v, a in ahead]),
            nearest_behind_accel_mps2=0.0 if behind is None else behind[2],
            coverage_behind_m=max(self.corner.range_m, self._v2x_free_m),
            side=self.side,
            lane_width_m=self.target_width_m,
        )

    # ----------------------------------------------------------------------------- parts
    def _radar_objects(self, report, lane_lo: float, lane_hi: float) -> tuple[list, list]:
        """(the forward radar's road users in the lane as (s, d, road speed, length, width),
        its detections outside the lane: they hide what is behind them)."""
        objects = []
        shadows = []
        in_path = report.in_path
        for det in report.detections:
            if det is not in_path and self._in_lane(det.d_m, det.width_m, lane_lo, lane_hi):
                objects.append((det.s_m, det.d_m, det.road_speed_mps, det.length_m, det.width_m))
            else:
                shadows.append(det)
        return objects, shadows

    def _add_v2x_objects(
        self,
        received: list[V2XObject],
        road,
        lane_lo: float,
        lane_hi: float,
        objects: list,
        in_path,
    ) -> None:
        """Append the ``received`` V2X objects in the lane that no radar object (nor the
        in-path obstacle) already stands for."""
        for o in received:
            s, d, ryaw = self._project(road, o.x_m, o.y_m, o.speed_mps)
            if not self._in_lane(d, o.width_m, lane_lo, lane_hi):
                continue
            if in_path is not None and _same(s, o.length_m, in_path.s_m, in_path.length_m):
                continue
            if any(
                _same(s, o.length_m, q[0], q[3]) and abs(d - q[1]) < FUSION_GATE_M for q in objects
            ):
                continue  # fused with a radar object
            objects.append((s, d, o.speed_mps * math.cos(o.yaw_rad - ryaw), o.length_m, o.width_m))

    def _nearest(
        self, objects: list, accel: list[float], s_f: float
    ) -> tuple[list[tuple[float, float, float]], tuple[float, float, float] | None]:
        """(gap, road speed, acceleration) of every road user ahead, nearest first
        (overlapping the ego's length counts as ahead, gap 0), and of the nearest behind the
        ego's rear (None: none)."""
        ahead: list[tuple[float, float, float]] = []
        behind: tuple[float, float, float] | None = None
        s_rear = s_f - self.ego_length_m
        for (s, _d, v, length, _width), a in zip(objects, accel):
            if s - 0.5 * length >= s_f - 1e-9 or s + 0.5 * length >= s_rear:
                ahead.append((max(s - 0.5 * length - s_f, 0.0), v, a))
            else:
                gap = s_rear - (s + 0.5 * length)
                if behind is None or gap < behind[0]:
                    behind = (gap, v, a)
        ahead.sort()
        return ahead, behind

    def _accelerations(self, time_s: float, objects: list) -> list[float]:
        """The acceleration along the road of each road user in the lane: its speed change
        over the last ``ACCEL_BASELINE_S`` (0 until it has been followed that long). A road
        user is the one of the last step whose predicted station lies within the fusion gate
        (the nearest)."""
        tracks = []
        accel: list[float] = []
        for s, _d, v, length, _width in objects:
            history = self._history(time_s, s, length)
            history.append((time_s, v))
            while len(history) > 1 and time_s - history[1][0] >= ACCEL_BASELINE_S - 1e-9:
                history.pop(0)
            t0, v0 = history[0]
            span = time_s - t0
            accel.append((v - v0) / span if span >= ACCEL_BASELINE_S - 1e-9 else 0.0)
            tracks.append((time_s, s, v, history))
        self._tracks = tracks
        return accel

    def _history(self, time_s: float, s_m: float, length_m: float) -> list[tuple[float, float]]:
        """The speed history of the road user of the last step at ``s_m`` (a new one: [])."""
        best, best_err = None, FUSION_GATE_M + 0.5 * length_m
        for t, s, v, history in self._tracks:
            err = abs(s + v * (time_s - t) - s_m)
            if err <= best_err:
                best, best_err = history, err
        return list(best) if best is not None else []

    @staticmethod
    def _in_lane(d_m: float, width_m: float, lane_lo: float, lane_hi: float) -> bool:
        return (
            min(d_m + 0.5 * width_m, lane_hi) - max(d_m - 0.5 * width_m, lane_lo) >= MIN_OVERLAP_M
        )

    def _corner_objects(
        self,
        front_xy,
        s_f: float,
        yaw_rad: float,
        road,
        bodies: Sequence[Body],
        lane_lo: float,
        lane_hi: float,
        known: list,
        in_path,
    ) -> list:
        """Road users the corner radars see in the lane (or beside the body), not already
        known."""
        c = self.corner
        if c.range_m <= 0.0:
            return []
        corners = self._sensors(front_xy, yaw_rad)[1:]
        fx, fy = corners[0][:2]
        out: list[tuple[float, float, float, float, float]] = []
        reach = c.range_m + self.ego_length_m
        for b in bodies:
            _, _, bx, by, b_yaw, speed_mps, length_m, width_m, _, box = b  # ``_BodyFields``
            _, _, _, _, _, _, _, _, _, radius_m = box
            if math.hypot(bx - fx, by - fy) > reach + radius_m:
                continue  # beyond both corner radars and not beside the body
            s, d, ryaw = self._project(road, bx, by, speed_mps)
            # the cheap tests first (all are pure): in the lane, not the obstacle, then seen
            if not self._in_lane(d, width_m, lane_lo, lane_hi):
                continue
            if in_path is not None and _same(s, length_m, in_path.s_m, in_path.length_m):
                continue
            beside = (
                s - 0.5 * length_m <= s_f + BESIDE_M
                and s + 0.5 * length_m >= s_f - self.ego_length_m - BESIDE_M
            )
            if not beside and not self._corners_see(box, corners):
                continue
            if any(
                _same(s, length_m, q[0], q[3]) and abs(d - q[1]) < FUSION_GATE_M
                for q in (*known, *out)
            ):
                continue
            out.append((s, d, speed_mps * math.cos(b_yaw - ryaw), length_m, width_m))
        return out

    @staticmethod
    def _corners_see(box: OrientedBox, corners: tuple[Sensor, Sensor]) -> bool:
        """Some part of the road user's box lies within a corner radar's range, at a bearing
        inside its field of view (its nearest point)."""
        bx, by, _, _, _, _, _, _, _, radius_m = box  # see ``_BoxFields``
        for ox, oy, look, half_fov, range_m in corners:
            if math.hypot(bx - ox, by - oy) > range_m + radius_m:
                continue
            px, py = nearest_point(box, ox, oy)
            if sees(ox, oy, look, half_fov, range_m, px, py):
                return True
        return False

    def _project(
        self, road, x_m: float, y_m: float, speed_mps: float
    ) -> tuple[float, float, float]:
        """Road-frame (s, d, road yaw) of a road user's centre; kept for standing ones."""
        if speed_mps != 0.0:
            return road.project(x_m, y_m)
        key = (x_m, y_m)
        hit = self._standing.get(key)
        if hit is None:
            if len(self._standing) > STANDING_CACHE:
                self._standing.clear()
            hit = self._standing[key] = road.project(x_m, y_m)
        return hit

    def _sensors(self, front_xy, yaw_rad: float) -> tuple[Sensor, Sensor, Sensor]:
        """(x, y, look, half field of view, range) of the forward and the two corner radars
        (on the lane's side: front-left and rear-left for the left lane)."""
        c = self.corner
        cy, sy = math.cos(yaw_rad), math.sin(yaw_rad)
        half_w = 0.5 * self.ego_width_m * self.side
        fx, fy = front_xy[0] - half_w * sy, front_xy[1] + half_w * cy  # front corner
        rx, ry = fx - self.ego_length_m * cy, fy - self.ego_length_m * sy  # rear corner
        half, bore = self._corner_half_fov, self._corner_bore
        return (
            (front_xy[0], front_xy[1], yaw_rad, self._radar_half_fov, self.radar_range_m),
            (fx, fy, yaw_rad + bore, half, c.range_m),
            (rx, ry, yaw_rad + math.pi - bore, half, c.range_m),
        )

    def _coverage(self, road, s_f: float, front_xy, yaw_rad: float, shadows: list) -> float:
        """Length of the lane ahead of the front bumper covered without a gap (module doc)."""
        boxes = []  # the detected objects as boxes along the road at their place
        for det in shadows:
            x, y, road_yaw = road.point_at(det.s_m, det.d_m)
            boxes.append(OrientedBox(x, y, road_yaw, det.length_m, det.width_m))
        radar, front_corner, rear_corner = self._sensors(front_xy, yaw_rad)
        corners = (front_corner, rear_corner)
        ox, oy = front_xy
        reach = max(self.radar_range_m, self.corner.range_m)
        best = math.inf
        for line in self.lines_m:
            covered, x = 0.0, BESIDE_M
            while x <= reach:
                px, py, _ = road.point_at(s_f + x, line)
                seen = sees(*radar, px, py) and not any(hides(box, ox, oy, px, py) for box in boxes)
                if not seen and not any(sees(*c, px, py) for c in corners):
                    break
                covered, x = x, x + COVERAGE_STEP_M
            best = min(best, covered)
        return max(best, self._v2x_free_m)


def _same(s_a: float, length_a: float, s_b: float, length_b: float) -> bool:
    """Two objects at these stations are one road user: centres within the fusion gate plus
    a quarter of their lengths (a long vehicle's reported centre may move along it)."""
    return abs(s_a - s_b) <= FUSION_GATE_M + 0.25 * (length_a + length_b)
