"""Reading a SUMO network file: the opposite lane of each lane, and checks SUMO lacks.

Our own streaming reader rather than ``sumolib.net.readNet``, because it is faster on the
path every run takes (``check_scenario`` before SUMO starts, once per run and per batch
case), keeps only what the checks need rather than the whole network in memory, and it
checks the lane numbers that SUMO itself crashes on.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from eoam_sumo.errors import InputError
from eoam_sumo.params import MU_MAX
from eoam_sumo.sim.roadframe import arclength, point_at, project
from eoam_sumo.sim.scenario.xmlread import xml_source


def read_net(path: Path) -> tuple[dict, dict]:
    """(lane id -> opposite lane id, normal edge id -> its lanes as (lane id, index, friction)),
    streaming through the network file once. Opposite: each ``<neigh>``, and for a two-way
    road built without them the leftmost lanes of an edge and its reverse edge (swapped
    junctions) when they lie side by side (``_side_by_side``). Friction: SUMO's default 1
    where a lane has none. InputError for a file
    that is missing, malformed, not a network, left-hand traffic, or has a lane number out of
    range (``_check_lane_numbers``)."""
    if not path.is_file():
        raise InputError(f"net-file {path} not found")
    opposite, lane_id, first = {}, None, True
    # normal edge id -> (from, to, leftmost lane (index, id, width, shape))
    edges: dict[str, tuple[str | None, str | None, tuple | None]] = {}
    edge_lanes: dict[str, list[tuple[str, int, float]]] = {}
    edge_id = None
    try:
        for event, elem in ET.iterparse(xml_source(path), events=("start", "end")):
            if first:
                if elem.tag != "net":
                    raise InputError(f"{path}: not a SUMO network (root element <{elem.tag}>)")
                if elem.get("lefthand") in ("true", "1"):
                    raise InputError(
                        f"{path}: a left-hand-traffic network: the EOAM changes lanes to the "
                        "left, where right-hand traffic has the opposite lane; not supported"
                    )
                first = False
            if event == "start" and elem.tag == "edge":
                edge_id = elem.get("id") if elem.get("function") in (None, "normal") else None
                if edge_id is not None:
                    edges[edge_id] = (elem.get("from"), elem.get("to"), None)
            elif event == "start" and elem.tag == "lane":
                lane_id = elem.get("id")
                _check_lane_numbers(path, lane_id, elem)
                if edge_id is not None:
                    frm, to, left = edges[edge_id]
                    index = int(elem.get("index", "0"))
                    friction = float(elem.get("friction", "1"))
                    edge_lanes.setdefault(edge_id, []).append((lane_id or "", index, friction))
                    if left is None or index > left[0]:
                        edges[edge_id] = (
                            frm,
                            to,
                            (index, lane_id, elem.get("width", "3.2"), elem.get("shape", "")),
                        )
            elif event == "start" and elem.tag == "neigh" and lane_id is not None:
                opposite[lane_id] = elem.get("lane")
            elif event == "end" and elem.tag in ("edge", "junction", "connection", "tlLogic"):
                elem.clear()
    except (ET.ParseError, OSError) as exc:
        raise InputError(f"{path}: malformed XML: {exc}") from exc
    # (parallel edges between the same two junctions: the last one read stands for them)
    by_ends = {(frm, to): left for frm, to, left in edges.values() if left is not None}
    for (frm, to), left in by_ends.items():
        back = by_ends.get((to, frm))
        if back is None or left[1] in opposite or back[1] in opposite:
            continue
        if _side_by_side(left, back):
            opposite[left[1]] = back[1]
            opposite[back[1]] = left[1]
    return opposite, edge_lanes


def _side_by_side(lane: tuple, other: tuple) -> bool:
    """The two lanes ((index, id, width, shape) as in the net file) lie next to each other: the
    other lane's centre line passes the middle of this one on its left at half the sum of their
    widths (within 0.3 m)."""
    try:
        a = np.array([[float(v) for v in p.split(",")[:2]] for p in lane[3].split()])
        b = np.array([[float(v) for v in p.split(",")[:2]] for p in other[3].split()])
        width = 0.5 * (float(lane[2]) + float(other[2]))
    except ValueError:
        return False
    if len(a) < 2 or len(b) < 2:
        return False
    mx, my, heading = point_at(a, 0.5 * arclength(a)[-1])
    bx, by, _ = point_at(b, project(b, mx, my)[0])  # the nearest point of the other lane
    left = -math.sin(heading) * (bx - mx) + math.cos(heading) * (by - my)
    return abs(left - width) <= 0.3


def _check_lane_numbers(path: Path, lane_id: str | None, lane: ET.Element) -> None:
    """A lane's numbers, where given, must be numbers in range (SUMO itself crashes on some
    that are not): ``friction`` in (0, MU_MAX], ``width``, ``length`` and ``speed`` > 0,
    ``index`` a whole number >= 0."""
    for key, top in (
        ("friction", MU_MAX),
        ("width", math.inf),
        ("length", math.inf),
        ("speed", math.inf),
        ("index", math.inf),
    ):
        text = lane.get(key)
        if text is None:
            continue
        try:
            value = int(text) if key == "index" else float(text)
        except ValueError:
            value = math.nan
        low_ok = value >= 0 if key == "index" else value > 0.0
        if not (low_ok and value <= top and math.isfinite(value)):
            bound = (
                "a whole number >= 0"
                if key == "index"
                else (f"a number in (0, {top:g}]" if math.isfinite(top) else "a number > 0")
            )
            raise InputError(f"{path}: lane '{lane_id}' {key}={text!r} must be {bound}")
