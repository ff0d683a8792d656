"""The road surface and lane markings of a SUMO network, near a run, for the bird's-eye view.

Reads the ``<lane>`` shapes of the network's normal edges (internal junction lanes too, as
surface without markings) that come within ``margin_m`` of a box: each lane becomes a
polygon (its centre line offset by half its width on each side); markings are the right
edge of each edge's first lane and the left edge of its last (solid), and the lines between
its lanes (dashed). A two-way road's two directions draw the same solid centre line.
Lanes that allow pedestrians only are pavements: surface of their own colour, no markings.
"""

from __future__ import annotations

import gzip
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from eoam_sumo.errors import InputError

DEFAULT_LANE_WIDTH_M = 3.2  # SUMO's default lane width


@dataclass
class RoadMap:
    """Lane polygons (road and pavement) and marking polylines, network coordinates [m]."""

    road: list[np.ndarray] = field(default_factory=list)
    pavement: list[np.ndarray] = field(default_factory=list)
    solid: list[np.ndarray] = field(default_factory=list)
    dashed: list[np.ndarray] = field(default_factory=list)


def _offset(line: np.ndarray, d_m: float) -> np.ndarray:
    """The polyline moved ``d_m`` to its left (negative: right), mitred at the vertices."""
    seg = np.diff(line, axis=0)
    seg /= np.maximum(np.hypot(seg[:, 0], seg[:, 1]), 1e-12)[:, None]
    normals = np.column_stack((-seg[:, 1], seg[:, 0]))
    vertex = np.vstack((normals[:1], normals[:-1] + normals[1:], normals[-1:]))
    vertex /= np.maximum(np.hypot(vertex[:, 0], vertex[:, 1]), 1e-12)[:, None]
    # keep the offset distance across a bend (mitre), capped for near-reversals
    cos_half = np.vstack(
        (
            np.ones((1, 1)),
            np.sum(vertex[1:-1] * normals[:-1], axis=1, keepdims=True),
            np.ones((1, 1)),
        )
    )
    return line + d_m * vertex / np.maximum(cos_half, 0.3)


def _shape(text: str) -> np.ndarray | None:
    try:
        pts = np.array([[float(v) for v in p.split(",")[:2]] for p in text.split()])
    except ValueError:
        return None
    return pts if len(pts) >= 2 else None


def read_road_map(
    net_file: Path, bbox: tuple[float, float, float, float], margin_m: float = 50.0
) -> RoadMap:
    """The lanes of ``net_file`` with a shape point within ``margin_m`` of ``bbox``
    (xmin, ymin, xmax, ymax) or crossing it. InputError naming the file if it cannot be read."""
    box = (bbox[0] - margin_m, bbox[1] - margin_m, bbox[2] + margin_m, bbox[3] + margin_m)
    out = RoadMap()
    opener = gzip.open if Path(net_file).suffix == ".gz" else open
    try:
        with opener(net_file, "rb") as source:
            _read_lanes(ET.iterparse(source, events=("start", "end")), box, out)
    except (ET.ParseError, OSError, ValueError) as exc:
        raise InputError(f"{net_file}: cannot be read as a SUMO network: {exc}") from exc
    return out


def _read_lanes(events, box: tuple, out: RoadMap) -> None:
    """The lanes of the parse ``events`` that reach into ``box`` into ``out``, by edge."""
    x0, y0, x1, y1 = box
    edge_lanes: list[tuple[np.ndarray, float, bool, int]] = []
    internal = False
    for event, elem in events:
        if event == "start" and elem.tag == "edge":
            internal = elem.get("function") == "internal"
            edge_lanes = []
        elif event == "end" and elem.tag == "lane":
            pts = _shape(elem.get("shape", ""))
            if pts is None:
                continue
            lo, hi = pts.min(axis=0), pts.max(axis=0)
            if hi[0] < x0 or lo[0] > x1 or hi[1] < y0 or lo[1] > y1:
                continue
            width = float(elem.get("width", DEFAULT_LANE_WIDTH_M))
            walk = elem.get("allow", "").split() == ["pedestrian"]
            edge_lanes.append((pts, width, walk, int(elem.get("index", "0"))))
        elif event == "end" and elem.tag == "edge":
            _add_edge(out, edge_lanes, internal)
            elem.clear()
        elif event == "end" and elem.tag in ("junction", "connection", "tlLogic"):
            elem.clear()


def _add_edge(out: RoadMap, lanes: list, internal: bool) -> None:
    """One edge's lanes (index order) into the map."""
    lanes = sorted(lanes, key=lambda lane: lane[3])
    drive = [lane for lane in lanes if not lane[2]]
    for pts, width, walk, _ in lanes:
        left, right = _offset(pts, 0.5 * width), _offset(pts, -0.5 * width)
        (out.pavement if walk else out.road).append(np.vstack((left, right[::-1])))
    if internal or not drive:
        return
    for k, (pts, width, _, _) in enumerate(drive):
        right = _offset(pts, -0.5 * width)
        (out.solid if k == 0 else out.dashed).append(right)
    pts, width = drive[-1][0], drive[-1][1]
    out.solid.append(_offset(pts, 0.5 * width))
