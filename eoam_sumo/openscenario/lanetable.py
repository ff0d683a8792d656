"""Which SUMO lanes carry each OpenDRIVE lane, and where along them each ``s`` lies.

netconvert splits a road into edges ``-<road>#k`` (along s) and ``<road>#k`` (against it), the
k-th edge of each direction covering the same stretch of the road: every lane section, and
wherever the lanes' widths change. Each edge's shape runs along the road (the border of lane
0), so the stretches' lengths along it, in the order of k and scaled to the road's length,
give each edge its part ``[s0, s1]`` of the reference line. A SUMO lane's shape vertices are
projected onto its edge's shape: each vertex gets its ``s``, so a lane that only exists in
later sections (a 2+1 road's overtaking lane) starts where its section starts, and a lane on
a curve beside straights maps ``s`` to its own length piece by piece (no single scale).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from itertools import accumulate, pairwise
from pathlib import Path

from eoam_sumo.openscenario.road import SumoLane, road_lengths

Point = tuple[float, float]


def _points(text: str) -> list[Point]:
    return [(float(x), float(y)) for x, y in (p.split(",")[:2] for p in text.split())]


def _cumulated(points: list[Point]) -> list[float]:
    return [0.0, *accumulate(math.dist(a, b) for a, b in pairwise(points))]


def _along(point: Point, line: list[Point], cum: list[float]) -> float:
    """The distance along ``line`` of the point of ``line`` nearest ``point``."""
    best, at = math.inf, 0.0
    for k, (a, b) in enumerate(pairwise(line)):
        dx, dy = b[0] - a[0], b[1] - a[1]
        seg = dx * dx + dy * dy
        f = 0.0 if seg == 0 else ((point[0] - a[0]) * dx + (point[1] - a[1]) * dy) / seg
        f = min(max(f, 0.0), 1.0)
        d = math.dist(point, (a[0] + f * dx, a[1] + f * dy))
        if d < best:
            best, at = d, cum[k] + f * (cum[k + 1] - cum[k])
    return at


def _section(edge: str) -> int:
    _, sep, k = edge.rpartition("#")
    return int(k) if sep and k.isdigit() else 0


def _read(net: Path) -> tuple[dict[str, list[Point]], list[tuple[str, ET.Element, tuple]]]:
    """Each plain edge's shape, and each lane with an ``origId`` (edge, element, key)."""
    root = ET.parse(net).getroot()
    nodes = {j.get("id"): (float(j.get("x", "0")), float(j.get("y", "0"))) for j in root.iter(
        "junction")}  # fmt: skip
    shapes, lanes = {}, []
    for edge in root.iter("edge"):
        if edge.get("function") == "internal":
            continue
        eid = edge.get("id", "")
        ends = [nodes.get(edge.get("from")), nodes.get(edge.get("to"))]
        shapes[eid] = _points(edge.get("shape", "")) or [p for p in ends if p is not None]
        for lane in edge.iter("lane"):
            orig = next(
                (p.get("value") for p in lane.iter("param") if p.get("key") == "origId"), None
            )
            if orig is not None and "_" in orig:
                road, _, lane_id = orig.rpartition("_")
                lanes.append((eid, lane, (road, int(lane_id))))
    return shapes, lanes


def _stretches(
    roads: dict[str, set[str]], shapes: dict[str, list[Point]], lengths: dict[str, float]
) -> dict[str, tuple[float, float]]:
    """Edge -> (s0, s1): the k-th stretch of its road, the stretches' lengths along the
    edges' shapes scaled to the road's length."""
    out: dict[str, tuple[float, float]] = {}
    for road, edges in roads.items():
        per_k: dict[int, float] = {}
        for e in edges:
            per_k.setdefault(_section(e), _cumulated(shapes[e])[-1])
        total = sum(per_k.values())
        scale = (lengths.get(road) or total) / total if total > 0 else 1.0
        start = 0.0
        bounds = {}
        for k in sorted(per_k):
            bounds[k] = (start, start + per_k[k] * scale)
            start = bounds[k][1]
        out |= {e: bounds[_section(e)] for e in edges}
    return out


def _lane(eid: str, lane: ET.Element, along: bool, edge_shape: list[Point], span) -> SumoLane:
    """One SUMO lane, its shape's vertices paired with their s (increasing)."""
    pts = _points(lane.get("shape", ""))
    cum = _cumulated(pts)
    length = float(lane.get("length", "0")) or cum[-1]
    pos = [c * length / cum[-1] if cum[-1] > 0 else 0.0 for c in cum]
    line_cum = _cumulated(edge_shape)
    ratio = (span[1] - span[0]) / line_cum[-1] if line_cum[-1] > 0 else 1.0
    d = [_along(p, edge_shape, line_cum) * ratio for p in pts]
    s = [span[0] + x for x in d] if along else [span[1] - x for x in d]
    if not along:
        s, pos = s[::-1], pos[::-1]
    s = list(accumulate(s, max))  # projections of a sane shape only grow; jitter does not
    return SumoLane(eid, int(lane.get("index", "0")), span[0], span[1], length, along,
                    tuple(s), tuple(pos))  # fmt: skip


def lane_table(net: Path, xodr: Path) -> dict[tuple[str, int], list[SumoLane]]:
    """(road, lane id) -> the SUMO lanes carrying it, in the order of s."""
    shapes, lanes = _read(net)
    roads: dict[str, set[str]] = {}
    for eid, _, (road, _lane_id) in lanes:
        roads.setdefault(road, set()).add(eid)
    spans = _stretches(roads, shapes, road_lengths(xodr))
    table: dict[tuple[str, int], list[SumoLane]] = {}
    for eid, lane, key in lanes:
        table.setdefault(key, []).append(_lane(eid, lane, key[1] < 0, shapes[eid], spans[eid]))
    return {key: sorted(items, key=lambda sl: sl.start_s_m) for key, items in table.items()}
