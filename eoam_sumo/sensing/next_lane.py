"""What the ego knows of the next lane: sensor coverage, road users in it, V2X fused in.

The next lane is the one left of the ego's original lane, between d = w/2 and 3 w/2 in that
lane's road frame (w the lane width). Three sensors look at it, all on the ego's body:

* the forward radar (``sim.radar``): its range and field of view from the front bumper, with
  the shadow of every other road user it sees (a ray through a nearer box does not reach the
  lane; the boxes are taken aligned with the road);
* two left corner radars (front-left and rear-left corners), each looking ``boresight_deg``
  outward from the ego's axis (forward and backward), with the range and field of view of a
  24 GHz lane-change-assist radar: Autoliv SRR "NB" sensor, user manual filed with the FCC,
  LCA mode: search range 4-80 m, azimuth -40 to +40 deg at the -6 dB points;
* V2X (``sensing.v2x``): objects of the equipped road users; when every road user is equipped
  the whole reception range counts as seen, less the distance the fastest road user covers
  while it may go unheard (``V2XSettings.blind_time_s``).

The strip of lane beside the ego's body, between the corner radars' fields, counts as seen: a
road user there came through a seen part (a tracker follows it), and is reported. Coverage is
measured on three lines along the lane (0.25 m inside each marker and its centre): the covered
length ahead is
where the first of them stops being covered without a gap. Geometry is that of a straight road
(stations and offsets in the road frame).

Road users in the lane are those whose box overlaps it by at least ``MIN_OVERLAP_M``, from the
forward radar's detections, the corner radars' and V2X, one object per road user (a V2X object
within ``FUSION_GATE_M`` of a radar object is the same road user), except the in-path obstacle
the EOAM is avoiding. Their speed or direction does not matter.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from eoam_sumo.decision.policy import NextLaneView
from eoam_sumo.sensing.v2x import V2XReceiver, V2XSettings

MIN_OVERLAP_M = 0.1  # a road user reaching this far into the lane is in it [m]
FUSION_GATE_M = 3.0  # radar and V2X objects closer than this (centre, plus half lengths) [m]
LINE_INSET_M = 0.25  # coverage lines: this far inside each lane marker [m]
STANDING_CACHE = 4096  # road-frame positions of standing road users kept at most
BESIDE_M = 2.0  # a road user within this of the ego's body along the road is beside it [m]


@dataclass(frozen=True)
class CornerRadarSettings:
    """Left corner radars (module doc: Autoliv 24 GHz SRR, LCA mode)."""

    range_m: float = 80.0
    fov_deg: float = 80.0  # full azimuth field (-40 to +40 deg)
    boresight_deg: float = 40.0  # outward from the ego's axis, forward (front) and back (rear)

    def __post_init__(self) -> None:
        if not (self.range_m >= 0.0 and 0.0 < self.fov_deg < 180.0
                and 0.0 <= self.boresight_deg <= 90.0):
            raise ValueError(f"corner radar settings out of range: {self}")


def _cot(angle_rad: float) -> float:
    if angle_rad <= 1e-12:
        return math.inf
    if angle_rad >= math.pi - 1e-12:
        return -math.inf
    return math.cos(angle_rad) / math.sin(angle_rad)


def cone_on_line(dy_m: float, boresight_rad: float, half_fov_rad: float,
                 range_m: float) -> tuple[float, float] | None:
    """The x-interval (along the road, from the sensor) of the line at lateral distance
    ``dy_m`` (left positive) inside the sensor's cone and range; None when none."""
    if range_m <= abs(dy_m):
        return None
    reach = math.sqrt(range_m * range_m - dy_m * dy_m)
    if abs(dy_m) < 1e-9:
        lo_ang, hi_ang = boresight_rad - half_fov_rad, boresight_rad + half_fov_rad
        fwd = lo_ang <= 0.0 <= hi_ang
        back = lo_ang <= math.pi <= hi_ang or lo_ang <= -math.pi <= hi_ang
        if fwd and back:
            return (-reach, reach)
        return (0.0, reach) if fwd else ((-reach, 0.0) if back else None)
    if dy_m < 0.0:  # mirror: the line to the right
        dy_m, boresight_rad = -dy_m, -boresight_rad
    lo = max(boresight_rad - half_fov_rad, 0.0)
    hi = min(boresight_rad + half_fov_rad, math.pi)
    if lo >= hi:
        return None
    x0, x1 = dy_m * _cot(hi), dy_m * _cot(lo)  # x = dy cot(angle), falling with the angle
    x0, x1 = max(x0, -reach), min(x1, reach)
    return (x0, x1) if x0 < x1 else None


def shadow_on_line(dy_m: float, box: tuple[float, float, float, float]) -> tuple | None:
    """The x-interval of the line at lateral ``dy_m`` hidden from a sensor at the origin by a
    road-aligned box (x0, x1, y0, y1) relative to it, beyond the box's near face."""
    x0, x1, y0, y1 = box
    if x1 <= 0.0 or dy_m == 0.0:
        return None
    angles = [math.atan2(y, x) for x in (x0, x1) for y in (y0, y1)]
    lo, hi = min(angles), max(angles)
    if dy_m < 0.0:
        dy_m, lo, hi = -dy_m, -hi, -lo
    lo, hi = max(lo, 0.0), min(hi, math.pi)
    if lo >= hi:
        return None
    a, b = max(dy_m * _cot(hi), x0, 0.0), dy_m * _cot(lo)
    if y0 <= dy_m <= y1:
        a = max(x0, 0.0)
    return (a, b) if a < b else None


def covered_from(intervals: list[tuple[float, float]], start: float) -> float:
    """How far from ``start`` the union of ``intervals`` covers without a gap (0 if ``start``
    itself is not covered)."""
    end = start
    for a, b in sorted(intervals):
        if a > end + 1e-9:
            break
        end = max(end, b)
    return end - start


def _minus(interval: tuple[float, float], holes: list) -> list[tuple[float, float]]:
    parts = [interval]
    for h0, h1 in holes:
        parts = [p for a, b in parts for p in ((a, min(b, h0)), (max(a, h1), b)) if p[0] < p[1]]
    return parts


class NextLaneSensing:
    """Builds the :class:`NextLaneView` of each step from the sensors (module doc)."""

    def __init__(self, *, opposing: bool, speed_limit_mps: float, lane_width_m: float,
                 radar_range_m: float, radar_fov_deg: float, ego_length_m: float,
                 ego_width_m: float, v2x: V2XSettings | None = None,
                 corner: CornerRadarSettings | None = None,
                 fastest_mps: float | None = None):
        self.opposing = opposing
        self.speed_limit_mps = speed_limit_mps
        self.lane_width_m = lane_width_m
        self.radar_range_m = radar_range_m
        self._radar_half_fov = math.radians(0.5 * radar_fov_deg)
        self.ego_length_m, self.ego_width_m = ego_length_m, ego_width_m
        v2x = v2x or V2XSettings()
        self.corner = corner or CornerRadarSettings()
        self.v2x = V2XReceiver(v2x) if v2x.enabled else None
        fastest = speed_limit_mps if fastest_mps is None else fastest_mps
        self._v2x_free_m = (v2x.range_m - fastest * v2x.blind_time_s()
                            if v2x.covers_all else 0.0)
        w = lane_width_m
        self.lines_m = (0.5 * w + LINE_INSET_M, w, 1.5 * w - LINE_INSET_M)
        self._standing: dict[tuple[float, float], tuple[float, float, float]] = {}

    @property
    def reach_m(self) -> float:
        """How far from the ego the road users it may sense can be (V2X or a corner radar)."""
        return max(self.v2x.settings.range_m if self.v2x is not None else 0.0,
                   self.corner.range_m + self.ego_length_m)

    def update(self, time_s: float, front_xy: tuple[float, float], yaw_rad: float, road,
               report, bodies: Sequence) -> NextLaneView:
        """The view at ``time_s``: ``report`` the forward radar's (``sim.radar.RadarReport``),
        ``bodies`` the ground truth of the road users around (for the corner radars and V2X),
        ``road`` the original lane's frame (``project(x, y) -> (s, d, road_yaw)``)."""
        s_f, d_f, road_yaw = road.project(*front_xy)
        e_yaw = math.remainder(yaw_rad - road_yaw, math.tau)
        w = self.lane_width_m
        lane_lo, lane_hi = 0.5 * w, 1.5 * w
        in_path = report.in_path
        objects = []  # (s, d, road speed, length, width) of road users in the lane
        shadows = []
        for det in report.detections:
            if det is in_path or (in_path is not None and det.index == in_path.index):
                shadows.append(self._box(det.s_m, det.d_m, det.length_m, det.width_m, s_f, d_f))
                continue
            if self._in_lane(det.d_m, det.width_m, lane_lo, lane_hi):
                objects.append((det.s_m, det.d_m, det.road_speed_mps, det.length_m,
                                det.width_m))
            else:
                shadows.append(self._box(det.s_m, det.d_m, det.length_m, det.width_m, s_f, d_f))
        objects += self._corner_objects(front_xy, s_f, yaw_rad, road, bodies, lane_lo,
                                        lane_hi, objects, in_path)
        if self.v2x is not None:
            self.v2x.update(time_s, front_xy, bodies)
            for o in self.v2x.objects(time_s):
                s, d, ryaw = self._project(road, o)
                if not self._in_lane(d, o.width_m, lane_lo, lane_hi):
                    continue
                if in_path is not None and _same(s, o.length_m, in_path.s_m, in_path.length_m):
                    continue
                if any(_same(s, o.length_m, q[0], q[3]) and abs(d - q[1]) < FUSION_GATE_M
                       for q in objects):
                    continue  # fused with a radar object
                objects.append((s, d, o.speed_mps * math.cos(o.yaw_rad - ryaw), o.length_m,
                                o.width_m))
        coverage = self._coverage(d_f, e_yaw, shadows)
        ahead = behind = None
        s_rear = s_f - self.ego_length_m
        for s, _d, v, length, _width in objects:
            if s - 0.5 * length >= s_f - 1e-9 or s + 0.5 * length >= s_rear:
                gap = max(s - 0.5 * length - s_f, 0.0)
                if ahead is None or gap < ahead[0]:
                    ahead = (gap, v)
            else:
                gap = s_rear - (s + 0.5 * length)
                if behind is None or gap < behind[0]:
                    behind = (gap, v)
        free = coverage if ahead is None else min(coverage, ahead[0])
        return NextLaneView(
            self.opposing, self.speed_limit_mps, coverage, free,
            None if ahead is None else ahead[0], None if ahead is None else ahead[1],
            None if behind is None else behind[0], None if behind is None else behind[1])

    # ----------------------------------------------------------------------------- parts
    @staticmethod
    def _in_lane(d_m: float, width_m: float, lane_lo: float, lane_hi: float) -> bool:
        return min(d_m + 0.5 * width_m, lane_hi) - max(d_m - 0.5 * width_m, lane_lo) \
            >= MIN_OVERLAP_M

    @staticmethod
    def _box(s, d, length, width, s_f, d_f) -> tuple[float, float, float, float]:
        return (s - 0.5 * length - s_f, s + 0.5 * length - s_f,
                d - 0.5 * width - d_f, d + 0.5 * width - d_f)

    def _corner_objects(self, front_xy, s_f, yaw_rad, road, bodies, lane_lo, lane_hi, known,
                        in_path) -> list:
        """Road users the corner radars see in the lane, not already known."""
        c = self.corner
        if c.range_m <= 0.0:
            return []
        cy, sy = math.cos(yaw_rad), math.sin(yaw_rad)
        half_w = 0.5 * self.ego_width_m
        fx, fy = front_xy[0] - half_w * sy, front_xy[1] + half_w * cy  # front-left corner
        rx, ry = fx - self.ego_length_m * cy, fy - self.ego_length_m * sy  # rear-left corner
        half_fov = math.radians(0.5 * c.fov_deg)
        bore = math.radians(c.boresight_deg)
        sensors = ((fx, fy, yaw_rad + bore), (rx, ry, yaw_rad + math.pi - bore))
        out: list[tuple[float, float, float, float, float]] = []
        s_front = s_f
        reach = c.range_m + self.ego_length_m
        for b in bodies:
            if math.hypot(b.x_m - fx, b.y_m - fy) > reach + b.box.radius_m:
                continue  # beyond both corner radars and not beside the body
            s, d, ryaw = self._project(road, b)
            beside = (s - 0.5 * b.length_m <= s_front + BESIDE_M
                      and s + 0.5 * b.length_m >= s_front - self.ego_length_m - BESIDE_M)
            if not beside and not any(self._corner_sees(b, *sensor, c.range_m, half_fov)
                                      for sensor in sensors):
                continue
            if not self._in_lane(d, b.width_m, lane_lo, lane_hi):
                continue
            if in_path is not None and _same(s, b.length_m, in_path.s_m, in_path.length_m):
                continue
            if any(_same(s, b.length_m, q[0], q[3]) and abs(d - q[1]) < FUSION_GATE_M
                   for q in (*known, *out)):
                continue
            out.append((s, d, b.speed_mps * math.cos(b.yaw_rad - ryaw), b.length_m, b.width_m))
        return out

    @staticmethod
    def _corner_sees(b, ox: float, oy: float, look: float, range_m: float,
                     half_fov: float) -> bool:
        """Some part of the road user's box lies within the corner radar's range, at a
        bearing inside its field of view (its nearest point)."""
        if math.hypot(b.x_m - ox, b.y_m - oy) > range_m + b.box.radius_m:
            return False
        px, py = b.box.nearest_point(ox, oy)
        if math.hypot(px - ox, py - oy) > range_m:
            return False
        return abs(math.remainder(math.atan2(py - oy, px - ox) - look, math.tau)) <= half_fov

    def _project(self, road, obj) -> tuple[float, float, float]:
        """Road-frame (s, d, road yaw) of a road user's centre; kept for standing ones."""
        if obj.speed_mps != 0.0:
            return road.project(obj.x_m, obj.y_m)
        key = (obj.x_m, obj.y_m)
        hit = self._standing.get(key)
        if hit is None:
            if len(self._standing) > STANDING_CACHE:
                self._standing.clear()
            hit = self._standing[key] = road.project(obj.x_m, obj.y_m)
        return hit

    def _coverage(self, d_f: float, e_yaw: float, shadows: list) -> float:
        """Length of the lane ahead of the front bumper covered without a gap (module doc)."""
        c = self.corner
        half_w = 0.5 * self.ego_width_m
        c_half = math.radians(0.5 * c.fov_deg)
        bore = math.radians(c.boresight_deg)
        best = math.inf
        for y in self.lines_m:
            dy = y - d_f
            parts = []
            cone = cone_on_line(dy, e_yaw, self._radar_half_fov, self.radar_range_m)
            if cone is not None:
                holes = [h for box in shadows if (h := shadow_on_line(dy, box)) is not None]
                parts += _minus(cone, holes)
            if c.range_m > 0.0:
                front = cone_on_line(dy - half_w, e_yaw + bore, c_half, c.range_m)
                rear = cone_on_line(dy - half_w, e_yaw + math.pi - bore, c_half, c.range_m)
                if front is not None:
                    parts.append(front)
                if rear is not None:
                    parts.append((rear[0] - self.ego_length_m, rear[1] - self.ego_length_m))
                if front is not None and rear is not None:  # beside the body: tracked
                    parts.append((rear[1] - self.ego_length_m, front[0]))
            if self._v2x_free_m > 0.0:
                parts.append((-self._v2x_free_m, self._v2x_free_m))
            best = min(best, covered_from(parts, 0.0))
        return best


def _same(s_a: float, length_a: float, s_b: float, length_b: float) -> bool:
    """Two objects at these stations are one road user: centres within the fusion gate plus
    a quarter of their lengths (a long vehicle's reported centre may move along it)."""
    return abs(s_a - s_b) <= FUSION_GATE_M + 0.25 * (length_a + length_b)
