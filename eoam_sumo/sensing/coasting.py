"""Track persistence for the ideal radar: an in-path road user lost from view at close range
stays a predicted ("coasted") object.

A narrow road user off the lane centre leaves the paper's 18 deg beam 5-8 m ahead (at 5 m
the beam covers +-0.8 m). A production tracker does not forget such an object when its
detections stop: it keeps the track, predicted at its last velocity, and reports it as
predicted rather than measured (Bar-Shalom, Li and Kirubarajan 2001, *Estimation with
Applications to Tracking and Navigation*, sec. 6.3: constant-velocity prediction; track
maintenance by missed-detection logic). Here:

* the nearest in-path road user of a scan is remembered (its ground-truth body: the ideal
  radar is a perfect tracker, so association is by identity);
* when a scan no longer detects it at all while its predicted box is still within the
  radar's range (it left the beam through its side, not through the far edge of the range),
  it is coasted: its box moved at its last velocity, measured from the radar as a detection
  would be, classified by the radar's rules;
* the coasted object is reported (``RadarReport.coasted``) while that prediction is in path
  (centre in the lane band and ahead of the ego's front bumper; classed ``in_path``, or
  oncoming and so head-on, as the radar's in-path obstacle is) and outside the beams; it
  ends when it is predicted out of the path or behind the ego, when the radar sees the
  object again, or when the prediction lies in a beam and nothing is seen there (the object
  did not go where it was predicted to go).

The work is done only while a track is lost; a scan that sees its in-path object costs one
assignment.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Protocol

from eoam_sumo.world.bodies import Body
from eoam_sumo.world.geometry import OrientedBox
from eoam_sumo.world.lanes import body_band_m


class Beams(Protocol):
    """What coasting asks of the radar (``eoam_sumo.sensing.radar.Radar``)."""

    def classify(
        self,
        ahead: bool,
        d_m: float,
        speed_mps: float,
        road_speed_mps: float,
        band_m: float,
        lane_width_m: float,
    ) -> str:
        """The radar's class of a target."""
        ...

    def head_on(self, category: str, ahead: bool, d_m: float, band_m: float) -> bool:
        """Whether a target of ``category`` is oncoming ahead in the lane band (in path)."""
        ...

    def covers(self, ox: float, oy: float, yaw_rad: float, px: float, py: float) -> bool:
        """Whether a point lies in one of the beams."""
        ...


class Coaster:
    """The coasting state of one radar: the last in-path body and the coasted one."""

    __slots__ = ("coasted", "coasted_t", "last", "last_t")

    def __init__(self) -> None:
        self.last: Body | None = None  # the nearest in-path body of the last scan that had one
        self.last_t: float | None = None
        self.coasted: Body | None = None  # the body as last seen, predicted from there
        self.coasted_t = 0.0

    def coast(
        self,
        radar: Beams,
        range_m: float,
        seen: Body | None,
        detected: Sequence[Body],
        ox: float,
        oy: float,
        yaw_rad: float,
        ego_vx: float,
        ego_vy: float,
        ego_s: float,
        project: Callable[[float, float], tuple[float, float, float]],
        band_m: float,
        lane_width_m: float,
        time_s: float | None,
    ) -> tuple | None:
        """The fields of the coasted object's ``Detection`` at ``time_s`` (None: none), given
        the scan's nearest in-path body ``seen`` and all ``detected`` bodies; called when
        ``seen`` is not the last scan's, or while an object is coasted."""
        if time_s is None:
            self.last = self.coasted = None
            return None
        lost, lost_t = self.last, self.last_t
        self.last, self.last_t = seen, time_s
        if seen is not None and self.coasted is not None and self.coasted.vid == seen.vid:
            self.coasted = None  # seen again
        if (
            lost is not None
            and (seen is None or seen.vid != lost.vid)
            and all(body.vid != lost.vid for body in detected)
        ):
            lost_t = time_s if lost_t is None else lost_t
            box = _predicted(lost, time_s - lost_t)
            px, py = box.nearest_point(ox, oy)
            nearer = self.coasted is None or _range(
                self.coasted, self.coasted_t, time_s, ox, oy
            ) > math.hypot(px - ox, py - oy)
            if math.hypot(px - ox, py - oy) < range_m and nearer:
                self.coasted, self.coasted_t = lost, lost_t
        body = self.coasted
        if body is None:
            return None
        fields = self._detection(
            radar,
            body,
            time_s,
            ox,
            oy,
            yaw_rad,
            ego_vx,
            ego_vy,
            ego_s,
            project,
            band_m,
            lane_width_m,
        )
        if fields is None:
            self.coasted = None
        return fields

    def _detection(
        self,
        radar,
        body,
        time_s,
        ox,
        oy,
        yaw_rad,
        ego_vx,
        ego_vy,
        ego_s,
        project,
        band_m,
        lane_width_m,
    ) -> tuple | None:
        """The coasted body's detection fields at ``time_s``, or None when the prediction is
        out of the path, behind the ego or in a beam (where it would have been seen)."""
        box = _predicted(body, time_s - self.coasted_t)
        s, d, road_yaw = project(box.x_m, box.y_m)
        road_speed = body.speed_mps * math.cos(box.yaw_rad - road_yaw)
        ahead = s > ego_s
        band_m = body_band_m(band_m, body.width_m)
        category = radar.classify(ahead, d, body.speed_mps, road_speed, band_m, lane_width_m)
        head_on = radar.head_on(category, ahead, d, band_m)
        px, py = box.nearest_point(ox, oy)
        if not (category == "in_path" or head_on) or radar.covers(ox, oy, yaw_rad, px, py):
            return None
        rng = math.hypot(px - ox, py - oy)
        lx, ly = (
            ((px - ox) / rng, (py - oy) / rng)
            if rng > 1e-9
            else (math.cos(yaw_rad), math.sin(yaw_rad))
        )
        tvx, tvy = body.speed_mps * box.cos_yaw, body.speed_mps * box.sin_yaw
        bx, by = math.cos(yaw_rad), math.sin(yaw_rad)
        return (
            -1,
            rng,
            (tvx - ego_vx) * lx + (tvy - ego_vy) * ly,
            math.atan2(bx * ly - by * lx, bx * lx + by * ly),
            s,
            d,
            road_speed,
            category,
            body.length_m,
            body.width_m,
            head_on,
        )


def _predicted(body: Body, dt_s: float) -> OrientedBox:
    """The body's box moved ``dt_s`` at its velocity (constant-velocity prediction)."""
    box = body.box
    step = body.speed_mps * dt_s
    return OrientedBox(
        box.x_m + step * box.cos_yaw,
        box.y_m + step * box.sin_yaw,
        box.yaw_rad,
        body.length_m,
        body.width_m,
    )


def _range(body: Body, t0_s: float, time_s: float, ox: float, oy: float) -> float:
    """Distance from (ox, oy) to the body's predicted box at ``time_s``."""
    px, py = _predicted(body, time_s - t0_s).nearest_point(ox, oy)
    return math.hypot(px - ox, py - oy)
