"""Putting vehicles into a running SUMO: the ego re-inserted at the requested speed, the added
oncoming car, and the ego's centre line along its route.

The ego is re-inserted as a copy of its route-file vehicle (route, type, departLane/departPos
and ``<param>``s kept; other attributes and its stops dropped), placed exactly with moveToXY
in the insertion step.
"""

from __future__ import annotations

import itertools
import math
import uuid
from dataclasses import dataclass

import numpy as np

from eoam_sumo.errors import InputError
from eoam_sumo.params import oncoming_sedan
from eoam_sumo.sim.roadframe import arclength, point_at, project
from eoam_sumo.sim.scenario import ROLE_KEY, ScenarioFiles, ScenarioOverrides, VehicleSpec
from eoam_sumo.sim.scenario.files import float_attr
from eoam_sumo.sim.scenario.values import number
from eoam_sumo.world.bodies import nav_angle_deg

EGO_SPEED_MODE = 32  # SUMO applies setSpeed and moveToXY without checks
ONCOMING_SPEED_MODE = 0  # constant speed even when the ego is mapped onto its lane
NO_LANE_CHANGES = 0
SPEED_LIMIT_WORDS = ("max", "desired", "speedLimit")


@dataclass(frozen=True)
class EgoStart:
    """Where and how the ego was inserted."""

    type_id: str
    route_edges: list
    lane_index: int
    lane_id: str
    lane_width_m: float
    left_lane_exists: bool  # a lane of its own direction or the opposite one to its left
    front_xy: tuple[float, float]  # front bumper at insertion
    centreline: np.ndarray  # (N, 2) of its start lane followed along its route
    route_lanes: tuple[str, ...] = ()  # the lane it follows on each route edge


def without_repeats(edges) -> list[str]:
    """Route edges with consecutive repeats dropped (a trip from an edge to itself)."""
    out: list[str] = []
    for edge in edges:
        if not out or edge != out[-1]:
            out.append(edge)
    return out


def lane_point(lane_api, lane_id: str, pos_m: float) -> tuple[float, float, float]:
    """(x, y, heading) of the point ``pos_m`` along a lane (SUMO's length, scaled to its
    shape)."""
    shape = np.asarray(lane_api.getShape(lane_id), dtype=float)
    scale = arclength(shape)[-1] / max(lane_api.getLength(lane_id), 1e-9)
    return point_at(shape, pos_m * scale)


def place_ego(
    api,
    errors: tuple,
    files: ScenarioFiles,
    overrides: ScenarioOverrides,
    ego_id: str,
    over_limit: dict,
) -> EgoStart:
    """Remove the ego SUMO loaded and insert it anew at its route file's lane and position
    with the requested speed (``over_limit`` as for :func:`insert`)."""
    veh, lanes = api.vehicle, api.lane
    spec = files.vehicles[ego_id]
    try:
        if not spec.routed:  # a trip holds only its end points until SUMO routes it
            veh.rerouteTraveltime(ego_id)
        edges = without_repeats(veh.getRoute(ego_id))
        type_id = veh.getTypeID(ego_id)
    except errors as exc:
        raise InputError(f"{spec.source}: SUMO did not load vehicle '{ego_id}': {exc}") from exc
    check_route_connected(api, spec, edges)
    lane_index = _ego_lane_index(api, spec, edges[0], type_id)
    lane_id = f"{edges[0]}_{lane_index}"
    lane_len = lanes.getLength(lane_id)
    pos = _ego_depart_pos(api, spec, lane_len, type_id)
    speed = _ego_speed(api, spec, lane_id, type_id, overrides)
    veh.remove(ego_id)
    insert(
        api,
        errors,
        ego_id,
        type_id,
        edges,
        lane_index,
        pos,
        speed,
        EGO_SPEED_MODE,
        spec.params,
        over_limit,
    )
    left_lane = lane_index < api.edge.getLaneNumber(edges[0]) - 1 or lane_id in files.opposite_lanes
    centreline, route_lanes = route_centreline(api, files, lane_id, edges, lane_index)
    return EgoStart(
        type_id,
        edges,
        lane_index,
        lane_id,
        float(lanes.getWidth(lane_id)),
        left_lane,
        lane_point(lanes, lane_id, pos)[:2],
        centreline,
        route_lanes,
    )


def check_route_connected(api, spec: VehicleSpec, edges: list[str]) -> None:
    """InputError naming the route file and the two edges when some lane of a route edge does
    not lead onto the next route edge at all (a route that skips an edge: SUMO checks it
    only when the vehicle departs)."""
    lanes = api.lane
    for edge, following in itertools.pairwise(edges):
        leads_on = any(
            lanes.getEdgeID(link[0]) == following
            for i in range(api.edge.getLaneNumber(edge))
            for link in lanes.getLinks(f"{edge}_{i}")
        )
        if not leads_on:
            raise InputError(
                f"{spec.source}: the route of vehicle '{spec.vid}' is not connected: edge "
                f"'{edge}' does not lead onto edge '{following}' (a route names every edge "
                "it drives, in order)"
            )


def _ego_lane_index(api, spec: VehicleSpec, edge: str, type_id: str) -> int:
    text = spec.attrs.get("departLane", "first")
    n_lanes = api.edge.getLaneNumber(edge)
    if text == "first":
        vclass = api.vehicletype.getVehicleClass(type_id)
        for i in range(n_lanes):
            allowed = api.lane.getAllowed(f"{edge}_{i}")
            if (not allowed or vclass in allowed) and vclass not in api.lane.getDisallowed(
                f"{edge}_{i}"
            ):
                return i
        raise InputError(f"{spec.source}: no lane of edge '{edge}' allows vehicle '{spec.vid}'")
    if not text.isdigit() or int(text) >= n_lanes:
        raise InputError(
            f"{spec.source}: vehicle '{spec.vid}' departLane={text!r}: the ego needs "
            f"a lane index below {n_lanes} (or 'first')"
        )
    return int(text)


def _ego_depart_pos(api, spec: VehicleSpec, lane_len: float, type_id: str) -> float:
    text = spec.attrs.get("departPos", "base")
    if text == "base":
        return min(api.vehicletype.getLength(type_id), lane_len)
    pos = float_attr(spec, "departPos", text)
    pos = pos + lane_len if pos < 0 else pos
    if not 0.0 <= pos <= lane_len:
        raise InputError(
            f"{spec.source}: vehicle '{spec.vid}' departPos={text!r} is off its "
            f"{lane_len:.2f} m start lane"
        )
    return pos


def _ego_speed(
    api, spec: VehicleSpec, lane_id: str, type_id: str, overrides: ScenarioOverrides
) -> float:
    if overrides.ego_speed_mps is not None:
        return overrides.ego_speed_mps
    text = spec.attrs.get("departSpeed", "0")
    if text in SPEED_LIMIT_WORDS:
        return min(api.lane.getMaxSpeed(lane_id), api.vehicletype.getMaxSpeed(type_id))
    speed = float_attr(spec, "departSpeed", text)
    return number(f"{spec.source}: vehicle '{spec.vid}' departSpeed", speed, minimum=0.0)


def route_centreline(
    api, files: ScenarioFiles, start_lane_id: str, route_edges: list, lane_index: int
) -> tuple[np.ndarray, tuple[str, ...]]:
    """Centre line of the ego's start lane followed along its route, lane by lane
    (``_next_lane``): where the next route edge goes on straight, the lane straight ahead of
    the ego's (a lane added beside it shifts SUMO's indices, which count from the right, and
    netconvert may connect the lane elsewhere); at a turn, over the connection (and the
    junction's internal lanes) to the lane it leads to. With the lane followed on each
    route edge."""
    lanes = api.lane
    lane = start_lane_id
    followed = [lane]
    points = [tuple(p) for p in lanes.getShape(lane)]
    for k, edge in enumerate(route_edges[1:], start=1):
        after = route_edges[k + 1] if k + 1 < len(route_edges) else None
        nxt, via = _next_lane(api, files, lane, edge, after, lane_index)
        for _ in range(8):  # a junction's internal lanes, until the next normal lane
            if not via or not via.startswith(":"):
                break
            points += [tuple(p) for p in lanes.getShape(via)]
            onward = lanes.getLinks(via)
            via = onward[0][0] if onward else None
        lane = nxt
        followed.append(lane)
        points += [tuple(p) for p in lanes.getShape(lane)]
    line = [points[0]]
    for p in points[1:]:
        if math.hypot(p[0] - line[-1][0], p[1] - line[-1][1]) > 1e-6:
            line.append(p)
    return np.array(line, dtype=float), tuple(followed)


#: A next edge whose lanes start within this of the ego's lane's heading goes on straight
#: (ours): its lane straight ahead is the ego's, connected or not.
STRAIGHT_ON_RAD = math.radians(20.0)


def _next_lane(api, files: ScenarioFiles, lane: str, edge: str, after: str | None, index: int):
    """The lane of route edge ``edge`` the ego's ``lane`` leads to, and the internal lane to
    it (None: straight on without one). Where ``edge`` goes on straight: the lane whose centre
    starts within half its width of the ego's lane's line (the connected one that continues
    onto the route's edge ``after`` when that one does not); none: the ego's lane ends there
    (a merge), refused. At a turn: the connected lane that continues onto ``after``, starts
    nearest, then has the same index."""
    lanes = api.lane
    shape = lanes.getShape(lane)
    (x0, y0), (x1, y1) = shape[-2][:2], shape[-1][:2]
    heading = math.atan2(y1 - y0, x1 - x0)
    links = {link[0]: link[4] for link in lanes.getLinks(lane) if lanes.getEdgeID(link[0]) == edge}
    straight, ahead = _lane_straight_ahead(api, edge, (x1, y1), heading)
    if ahead is not None and (after is None or _continues(api, ahead, after) or not links):
        return ahead, links.get(ahead) or None
    if not links or (straight and ahead is None):
        raise InputError(
            f"{files.net_file}: the ego's lane {lane} does not continue onto "
            f"edge '{edge}' of its route (no connection, or it merges into another lane: "
            "the lane ends); start the ego in a lane that continues"
        )
    best = min(
        links,
        key=lambda k: (
            after is not None and not _continues(api, k, after),
            round(math.dist((x1, y1), lanes.getShape(k)[0][:2]), 1),
            abs(int(k.rsplit("_", 1)[1]) - index),
        ),
    )
    return best, links[best]


def _continues(api, lane: str, edge: str) -> bool:
    """Whether ``lane`` has a connection onto ``edge``."""
    return any(api.lane.getEdgeID(link[0]) == edge for link in api.lane.getLinks(lane))


def _lane_straight_ahead(api, edge: str, end: tuple, heading: float) -> tuple[bool, str | None]:
    """Whether ``edge`` goes on straight (a lane of it starts within ``STRAIGHT_ON_RAD`` of
    ``heading``), and its lane whose start lies on the line ahead of ``end`` (within half its
    width across it), if any."""
    c, s = math.cos(heading), math.sin(heading)
    straight, best, best_d = False, None, math.inf
    for k in range(api.edge.getLaneNumber(edge)):
        lane = f"{edge}_{k}"
        shape = api.lane.getShape(lane)
        (xa, ya), (xb, yb) = shape[0][:2], shape[1][:2]
        if abs(math.remainder(math.atan2(yb - ya, xb - xa) - heading, math.tau)) > STRAIGHT_ON_RAD:
            continue
        straight = True
        across = abs(-(xa - end[0]) * s + (ya - end[1]) * c)
        if across <= 0.5 * api.lane.getWidth(lane) and across < best_d:
            best, best_d = lane, across
    return straight, best


def let_fast_vehicles_depart(api, errors: tuple, files: ScenarioFiles, ego_id: str) -> None:
    """Let every vehicle of the scenario's files that has not departed yet, the ego aside,
    depart at a ``departSpeed`` above its departure edge's speed limit: SUMO chooses such a
    vehicle a speed factor that allows the speed when its type has a speed deviation
    (``speedDev`` > 0) and refuses the others ("Departure speed for vehicle ... is too high
    for the departure edge"); those get that speed factor here (departSpeed / the edge's
    lowest lane speed limit), so they too depart at their speed and keep it as their desired
    speed. A speed above the vehicle type's ``maxSpeed`` stays SUMO's to refuse."""
    veh = api.vehicle
    try:
        pending = set(veh.getLoadedIDList()) - set(veh.getIDList())
    except errors:
        return
    for vid, spec in files.vehicles.items():
        speed = _given_depart_speed(spec)
        if vid == ego_id or vid not in pending or speed is None:
            continue
        try:
            if api.vehicletype.getSpeedDeviation(veh.getTypeID(vid)) > 0.0:
                continue  # SUMO chooses its speed factor itself
            limit_mps = _edge_speed_limit(api, veh.getRoute(vid)[0])
            if speed > limit_mps * veh.getSpeedFactor(vid):
                veh.setSpeedFactor(vid, speed / limit_mps)
        except errors:
            continue  # SUMO reports what is wrong with this vehicle when it departs


def _given_depart_speed(spec: VehicleSpec) -> float | None:
    """A vehicle's ``departSpeed`` when it is a number > 0, else None."""
    try:
        speed = float(spec.attrs.get("departSpeed", ""))
    except ValueError:
        return None
    return speed if math.isfinite(speed) and speed > 0.0 else None


def _edge_speed_limit(api, edge: str) -> float:
    """The lowest speed limit of an edge's lanes [m/s]."""
    return min(
        float(api.lane.getMaxSpeed(f"{edge}_{i}")) for i in range(api.edge.getLaneNumber(edge))
    )


def add_oncoming(
    api,
    errors: tuple,
    files: ScenarioFiles,
    overrides: ScenarioOverrides,
    ego: EgoStart,
    over_limit: dict,
) -> str:
    """Insert the oncoming car of ``overrides.oncoming_start_m`` in the lane opposite the
    ego's, its front bumper that far ahead of the ego's along the road; its id."""
    distance = overrides.oncoming_start_m
    assert distance is not None  # called only when the overrides ask for an oncoming car
    px, py = _ahead_of_ego(ego, distance)
    edges, lane_id, pos = _opposite_start(api, files, ego, px, py)
    _ensure_oncoming_type(api.vehicletype)
    vid, n = "oncoming", 0
    while vid in files.vehicles:
        n += 1
        vid = f"oncoming.{n}"
    index = int(lane_id.rsplit("_", 1)[1])  # SUMO lane ids are <edge>_<index>
    insert(
        api,
        errors,
        vid,
        "oncoming",
        edges,
        index,
        pos,
        overrides.oncoming_speed_mps,
        ONCOMING_SPEED_MODE,
        {ROLE_KEY: "oncoming"},
        over_limit,
    )
    return vid


def _ahead_of_ego(ego: EgoStart, distance_m: float) -> tuple[float, float]:
    """The point of the ego's centre line ``distance_m`` ahead of its front bumper;
    InputError when the route ends before it."""
    s_ego, _ = project(ego.centreline, *ego.front_xy)
    total = arclength(ego.centreline)[-1]
    if s_ego + distance_m > total:
        raise InputError(
            f"oncoming_start_m={distance_m:g}: the ego's route ends "
            f"{total - s_ego:.1f} m ahead of the ego"
        )
    px, py, _ = point_at(ego.centreline, s_ego + distance_m)
    return px, py


def _opposite_start(
    api, files: ScenarioFiles, ego: EgoStart, px: float, py: float
) -> tuple[list[str], str, float]:
    """(route edges, lane id, position on the lane [m]) of the oncoming car: on the opposite
    lane of the ego's route nearest (px, py), its route the opposite edges back from there to
    the first route edge without an opposite lane."""
    lanes = api.lane
    opposite = []  # per route edge: the opposite lane of its leftmost lane, or None
    for edge in ego.route_edges:
        leftmost = f"{edge}_{api.edge.getLaneNumber(edge) - 1}"
        opposite.append(files.opposite_lanes.get(leftmost))
    candidates = [
        (project(np.asarray(lanes.getShape(o), float), px, py), k, o)
        for k, o in enumerate(opposite)
        if o is not None
    ]
    if not candidates:
        names = ", ".join(f"'{e}'" for e in ego.route_edges)
        raise InputError(
            f"{files.net_file}: no oncoming car (--oncoming-m, oncoming_start_m): the ego's "
            f"road is one-way, no lane of the other direction lies beside its route (edges "
            f"{names})"
        )
    (s_opp, _), k, lane_id = min(candidates, key=lambda c: c[0][1])
    edges = []
    for o in reversed(opposite[: k + 1]):
        if o is None:
            break
        edges.append(lanes.getEdgeID(o))
    shape = np.asarray(lanes.getShape(lane_id), dtype=float)
    pos = s_opp * lanes.getLength(lane_id) / arclength(shape)[-1]
    return edges, lane_id, pos


def _ensure_oncoming_type(types) -> None:
    """The vehicle type ``oncoming`` (the oncoming sedan's dimensions), made once."""
    if "oncoming" not in types.getIDList():
        dims = oncoming_sedan()
        types.copy("DEFAULT_VEHTYPE", "oncoming")
        types.setLength("oncoming", dims.length_m)
        types.setWidth("oncoming", dims.width_m)


def insert(
    api,
    errors: tuple,
    vid: str,
    type_id: str,
    edges: list,
    lane_index: int,
    pos: float,
    speed: float,
    speed_mode: int,
    params: dict,
    over_limit: dict,
) -> None:
    """Add ``vid`` on a fresh route over ``edges`` at ``pos`` of its first lane, placed there
    exactly with ``moveToXY`` and moving at ``speed`` from the insertion step on. A vehicle
    SUMO lets depart only at rest (above its lane's or type's limit) is entered in
    ``over_limit`` (id -> speed), to be given its speed after the insertion step."""
    veh = api.vehicle
    route_id = f"eoam.route.{vid}.{uuid.uuid4().hex[:8]}"
    api.route.add(route_id, edges)

    def add(depart_speed: str) -> None:
        veh.add(
            vid,
            route_id,
            type_id,
            depart="now",
            departLane=str(lane_index),
            departPos=repr(float(pos)),
            departSpeed=depart_speed,
        )

    try:
        add(repr(float(speed)))
    except errors as exc:
        if "too high" not in str(exc):
            raise
        # SUMO refuses a departure above the lane's limit times the vehicle's speed factor,
        # or above its type's maximum: depart at rest, with room to go faster; the speed
        # set below applies from the insertion step on (speed modes without limits)
        add("0")
        limit = api.lane.getMaxSpeed(f"{edges[0]}_{lane_index}")
        veh.setSpeedFactor(vid, max(veh.getSpeedFactor(vid), speed / limit * (1.0 + 1e-6)))
        veh.setMaxSpeed(vid, max(veh.getMaxSpeed(vid), speed * (1.0 + 1e-6)))
        over_limit[vid] = speed
    for key, value in params.items():
        veh.setParameter(vid, key, value)
    veh.setSpeedMode(vid, speed_mode)
    veh.setLaneChangeMode(vid, NO_LANE_CHANGES)
    x, y, heading = lane_point(api.lane, f"{edges[0]}_{lane_index}", pos)
    # no lane index as a hint: on some nets converted from OpenDRIVE SUMO 1.28 maps a hinted
    # index n onto another lane of the edge (lanes 1 and 2 of 3 swapped); the point lies on
    # the lane's centre line, which SUMO's nearest-lane search on the route finds
    veh.moveToXY(vid, edges[0], -1, x, y, nav_angle_deg(heading), keepRoute=1)
    veh.setPreviousSpeed(vid, speed)
    veh.setSpeed(vid, speed)
