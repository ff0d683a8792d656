"""Where an OpenDRIVE lane position lies on the SUMO network, and back.

A position is (road, lane id, s, offset): ``s`` along the road's reference line, ``offset``
from the lane's centre, positive to the left of the direction of s (OpenSCENARIO's
``LanePosition``). :mod:`.road`'s table gives the SUMO lane and the position along it; the
lane's shape (sumolib) gives the point and the heading.
"""

from __future__ import annotations

import math
from bisect import bisect_right
from itertools import accumulate, pairwise
from pathlib import Path

from eoam_sumo.openscenario.lanetable import lane_table
from eoam_sumo.openscenario.road import SumoLane, locate


class _Shape:
    """A SUMO lane's centre line: points, cumulated lengths, per metre of the lane's length."""

    def __init__(self, points: list, lane_length_m: float, width_m: float) -> None:
        xy = [(float(x), float(y)) for x, y in points]
        self.xy = xy[:1] + [b for a, b in pairwise(xy) if math.dist(a, b) > 1e-6]
        if len(self.xy) < 2:
            self.xy = xy[:1] * 2
        seg = [math.dist(a, b) for a, b in zip(self.xy, self.xy[1:], strict=False)]
        self.cum = [0.0, *accumulate(seg)]
        self.factor = self.cum[-1] / lane_length_m if lane_length_m > 0 else 1.0
        self.width_m = width_m

    def at(self, pos_m: float, offset_m: float) -> tuple[float, float, float]:
        """(x, y, heading) ``pos_m`` along the lane, ``offset_m`` to its left (before its
        start or past its end: straight on along its first or last segment)."""
        d = pos_m * self.factor
        i = max(min(bisect_right(self.cum, d) - 1, len(self.cum) - 2), 0)
        (x0, y0), (x1, y1) = self.xy[i], self.xy[i + 1]
        heading = math.atan2(y1 - y0, x1 - x0)
        f = (d - self.cum[i]) / max(self.cum[i + 1] - self.cum[i], 1e-12)
        x, y = x0 + f * (x1 - x0), y0 + f * (y1 - y0)
        return x - offset_m * math.sin(heading), y + offset_m * math.cos(heading), heading


class LaneMap:
    """The road's lanes: OpenDRIVE positions to SUMO points and the ego's SUMO lane to s."""

    def __init__(self, net_file: Path, xodr: Path) -> None:
        import sumolib

        self.table = lane_table(net_file, xodr)
        net = sumolib.net.readNet(str(net_file))
        self._shapes: dict[str, _Shape] = {}
        self._back: dict[str, tuple[str, int, SumoLane]] = {}
        for (road, lane), lanes in self.table.items():
            for sl in lanes:
                sumo = net.getEdge(sl.edge).getLanes()[sl.index]
                lane_id = sumo.getID()
                self._shapes[lane_id] = _Shape(sumo.getShape(), sumo.getLength(), sumo.getWidth())
                self._back[lane_id] = (road, lane, sl)

    def has(self, road: str, lane: int) -> bool:
        return (road, lane) in self.table

    def locate(self, road: str, lane: int, s_m: float) -> tuple[str, float]:
        """(SUMO lane id, position along it) of the lane's centre at ``s_m`` (clamped to the
        lane's ends: an entity driven past the end of the road stays at it)."""
        lanes = self.table[(road, lane)]
        s_m = min(max(s_m, lanes[0].start_s_m), lanes[-1].end_s_m)
        sl, pos = locate(self.table, road, lane, s_m, f"road {road} lane {lane}")
        return f"{sl.edge}_{sl.index}", pos

    def point(
        self, road: str, lane: int, s_m: float, offset_m: float
    ) -> tuple[float, float, float]:
        """(x, y, heading of the direction of s) of a lane position."""
        lane_id, pos = self.locate(road, lane, s_m)
        x, y, heading = self._shapes[lane_id].at(pos, offset_m if lane < 0 else -offset_m)
        return (x, y, heading) if lane < 0 else (x, y, heading + math.pi)

    def width_m(self, road: str, lane: int, s_m: float) -> float:
        return self._shapes[self.locate(road, lane, s_m)[0]].width_m

    def shift_m(self, road: str, lane_from: int, lane_to: int, s_m: float) -> float:
        """The centre of ``lane_to`` to the left of the centre of ``lane_from`` (along s)."""
        x0, y0, h = self.point(road, lane_from, s_m, 0.0)
        x1, y1, _ = self.point(road, lane_to, s_m, 0.0)
        return -(x1 - x0) * math.sin(h) + (y1 - y0) * math.cos(h)

    def road_position(self, lane_id: str, pos_m: float) -> tuple[str, int, float] | None:
        """(road, lane id, s) of a SUMO lane position (None off the scenario's lanes)."""
        found = self._back.get(lane_id)
        if found is None:
            return None
        road, lane, sl = found
        return road, lane, sl.s_m(pos_m)
