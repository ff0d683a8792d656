"""Every test point as a SUMO scenario: one shared network, one route file and sumocfg each.

The network (built with netconvert through :mod:`eoam_sumo.netbuild`) is the straight 4 km
two-way road of ``networks/highway`` (ego lane ``E0_0``, centre y = -1.75 m, with the
opposite lane as its neighbour, so the EOAM can change lanes) plus, for every lateral target
offset, a one-lane edge under the ego lane: ``T<k>`` eastbound (the target ahead) and
``H<k>`` westbound (the head-on target), their lane centre at y = -1.75 + offset. SUMO keeps
a vehicle on its lane's centre, so the offset lane places the target at its overlap; the
radar and the contact test see it where it is (geometry, never lane ids). A CCFhol point's
target drives its own westbound edge ``L<n>`` whose shape is the scripted lane change
(``lane_change.path_points``): it starts ``HOL_SHIFT_M`` left of its end offset and follows
the path into the ego lane, so SUMO moves it along the path at its speed; the obstruction
vehicle it pulls out from behind drives the opposite lane ``-E0``.

The target's speed profile is a scripted stop (``eoam.aro_hold_s``, ``eoam.aro_decel_mps2``,
docs/scenarios.md): stationary (departs at 0), constant (holds for the whole run) or braking
at the given deceleration after a hold.
"""

from __future__ import annotations

from pathlib import Path

from eoam_sumo.fileio import write_atomic
from eoam_sumo.netbuild import build_network, sumocfg_text
from eoam_sumo.protocols.lane_change import path_points
from eoam_sumo.protocols.points import (
    FOREVER_S,
    GVT_LENGTH_M,
    GVT_WIDTH_M,
    HEAD_ON_STARTUP_S,
    HOL_SHIFT_M,
    HOL_SOV_HEADWAY_S,
    SOV_LENGTH_M,
    SOV_WIDTH_M,
    TestPoint,
)

ROAD_M = 4000.0
EGO_LANE_Y_M = -1.75
EGO_FRONT_X_M = 100.0
DEPART_S = 1.0
STOPPED_DECEL_MPS2 = 10.0  # a stationary target's script: held at 0 from its departure
#: The ego's SUMO class: the targets' edges disallow it, so that SUMO's placing of the ego
#: (``moveToXY``, which measures the distance to every lane the ego may use within 100 m)
#: looks only at the road's two lanes, not at the targets' rails under the ego lane.
EGO_VCLASS = "custom1"


def offset_edges(points: list[TestPoint]) -> dict[float, int]:
    """Each distinct target offset -> the index k of its edges ``T<k>``/``H<k>``."""
    return {off: k for k, off in enumerate(sorted({p.offset_m for p in points}))}


def lane_change_edges(points: list[TestPoint]) -> dict[str, int]:
    """Each CCFhol point's id -> the index n of its edge ``L<n>``."""
    return {p.point_id: n for n, p in enumerate(p for p in points if p.lane_change)}


def lane_change_start_x_m(point: TestPoint) -> float:
    """Where the target's lane change begins: its front's start, 8 s of its speed on."""
    return EGO_FRONT_X_M + point.gap_m - HEAD_ON_STARTUP_S * point.target_speed_kmh / 3.6


def lane_change_shape(point: TestPoint) -> list[tuple[float, float]]:
    """The CCFhol target's westbound path: straight HOL_SHIFT_M left of its end offset, the
    lane change from ``lane_change_start_x_m`` on, then straight at the end offset."""
    end_y = EGO_LANE_Y_M + point.offset_m
    start_x = lane_change_start_x_m(point)
    path = path_points(point.target_speed_kmh, HOL_SHIFT_M)
    shape = [(ROAD_M, end_y + HOL_SHIFT_M)]
    shape += [(start_x - along, end_y + HOL_SHIFT_M - left) for along, left in path]
    return [*shape, (0.0, end_y)]


def _lane_change_sources(points: list[TestPoint]) -> tuple[list[str], list[str]]:
    """Nodes and edges of every CCFhol target's path."""
    nodes, edges = [], []
    for pid, n in lane_change_edges(points).items():
        shape = lane_change_shape(next(p for p in points if p.point_id == pid))
        (xe, ye), (xw, yw) = shape[0], shape[-1]
        nodes += [
            f'<node id="le{n}" x="{xe:.2f}" y="{ye:.4f}"/>',
            f'<node id="lw{n}" x="{xw:.2f}" y="{yw:.4f}"/>',
        ]
        text = " ".join(f"{x:.3f},{y:.4f}" for x, y in shape)
        edges.append(
            f'<edge id="L{n}" from="le{n}" to="lw{n}" numLanes="1" speed="50.00" width="2.00"'
            f' spreadType="center" disallow="{EGO_VCLASS}" shape="{text}">'
            '<lane index="0" friction="1.00"/></edge>'
        )
    return nodes, edges


def _network_sources(folder: Path, offsets: dict[float, int], points: list[TestPoint]) -> Path:
    nodes = ['<node id="west" x="0.00" y="0.00"/>', f'<node id="east" x="{ROAD_M:.2f}" y="0.00"/>']
    edges = [
        '<edge id="E0" from="west" to="east" numLanes="1" speed="50.00" width="3.50">'
        '<lane index="0" friction="1.00"><neigh lane="-E0_0"/></lane></edge>',
        '<edge id="-E0" from="east" to="west" numLanes="1" speed="50.00" width="3.50">'
        '<lane index="0" friction="1.00"><neigh lane="E0_0"/></lane></edge>',
    ]
    for off, k in offsets.items():
        y = EGO_LANE_Y_M + off
        # T and H get their own nodes: netconvert would treat a pair sharing nodes as one
        # two-way road and move each lane off the line by half its width
        for tag in ("t", "h"):
            nodes += [
                f'<node id="{tag}w{k}" x="0.00" y="{y:.4f}"/>',
                f'<node id="{tag}e{k}" x="{ROAD_M:.2f}" y="{y:.4f}"/>',
            ]
        for eid, a, b in ((f"T{k}", f"tw{k}", f"te{k}"), (f"H{k}", f"he{k}", f"hw{k}")):
            edges.append(
                f'<edge id="{eid}" from="{a}" to="{b}" numLanes="1" speed="50.00" width="2.00"'
                f' spreadType="center" disallow="{EGO_VCLASS}"><lane index="0" friction="1.00"/>'
                "</edge>"
            )
    hol_nodes, hol_edges = _lane_change_sources(points)
    nodes, edges = nodes + hol_nodes, edges + hol_edges
    head = '<?xml version="1.0" encoding="UTF-8"?>\n'
    write_atomic(
        folder / "protocol.nod.xml", head + "<nodes>\n" + "\n".join(nodes) + "\n</nodes>\n"
    )
    write_atomic(
        folder / "protocol.edg.xml", head + "<edges>\n" + "\n".join(edges) + "\n</edges>\n"
    )
    return folder / "protocol.nod.xml"


VTYPES = f"""<?xml version="1.0" encoding="UTF-8"?>
<!-- ego: the sedan (scenarios/vtypes.add.xml); gvt: Euro NCAP's Global Vehicle Target,
     {GVT_LENGTH_M} x {GVT_WIDTH_M} m; sov: CCFhol's obstruction vehicle
     (vectorgrp/OSC-NCAP-scenarios Vehicles.xosc NCAP_GlobalVehicleTarget,
     NCAP_ObstructionVehicle_Large). -->
<additional>
    <vType id="ego" vClass="{EGO_VCLASS}" length="4.92" width="1.85" minGap="2.00" maxSpeed="60.00"
           accel="4.00" decel="9.00" emergencyDecel="12.00" sigma="0" speedDev="0"/>
    <vType id="gvt" vClass="passenger" length="{GVT_LENGTH_M}" width="{GVT_WIDTH_M}"
           minGap="1.00" maxSpeed="50.00" accel="2.50" decel="10.00" emergencyDecel="12.00"
           sigma="0" speedDev="0"/>
    <vType id="sov" vClass="passenger" length="{SOV_LENGTH_M}" width="{SOV_WIDTH_M}"
           minGap="1.00" maxSpeed="50.00" accel="2.50" decel="10.00" emergencyDecel="12.00"
           sigma="0" speedDev="0"/>
</additional>
"""


def _obstruction(point: TestPoint) -> str:
    """CCFhol's obstruction vehicle on the opposite lane, F ahead of the target (its rear F
    before the target's front), at the target's speed for the whole run."""
    if not point.lane_change:
        return ""
    tgt_mps = point.target_speed_kmh / 3.6
    front_x = EGO_FRONT_X_M + point.gap_m - HOL_SOV_HEADWAY_S * tgt_mps - SOV_LENGTH_M
    return f"""    <route id="sov_route" edges="-E0"/>
    <vehicle id="obstruction" type="sov" route="sov_route" depart="{DEPART_S:.2f}"
             departLane="0" departPos="{ROAD_M - front_x:.3f}" departSpeed="{tgt_mps:.6f}"
             insertionChecks="none">
        <param key="eoam.aro_hold_s" value="{FOREVER_S:g}"/>
        <param key="eoam.aro_decel_mps2" value="{STOPPED_DECEL_MPS2:g}"/>
    </vehicle>
"""


def _routes(point: TestPoint, k: int) -> str:
    """The ego and the target of one point (SUMO places a vehicle by its front bumper);
    ``k``: the target's edge index (``L<k>`` for a lane change, else ``T<k>``/``H<k>``)."""
    ego_mps, tgt_mps = point.ego_speed_kmh / 3.6, point.target_speed_kmh / 3.6
    if point.lane_change:
        edge, pos = f"L{k}", ROAD_M - (EGO_FRONT_X_M + point.gap_m)
    elif point.head_on:
        edge, pos = f"H{k}", ROAD_M - (EGO_FRONT_X_M + point.gap_m)
    else:
        edge, pos = f"T{k}", EGO_FRONT_X_M + point.gap_m + GVT_LENGTH_M
    hold, decel = point.hold_s, point.target_decel_mps2
    if point.target_speed_kmh == 0.0:
        hold, decel = 0.0, STOPPED_DECEL_MPS2
    elif decel == 0.0:
        decel = STOPPED_DECEL_MPS2  # never reached: the hold outlasts the run
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<!-- {point.protocol} {point.test}: {point.point_id} -->
<routes>
    <route id="ego_route" edges="E0"/>
    <route id="target_route" edges="{edge}"/>
    <vehicle id="ego" type="ego" route="ego_route" depart="{DEPART_S:.2f}" departLane="0"
             departPos="{EGO_FRONT_X_M:.2f}" departSpeed="{ego_mps:.6f}" insertionChecks="none"/>
    <vehicle id="target" type="gvt" route="target_route" depart="{DEPART_S:.2f}" departLane="0"
             departPos="{pos:.3f}" departSpeed="{tgt_mps:.6f}" insertionChecks="none">
        <param key="eoam.aro_hold_s" value="{hold:g}"/>
        <param key="eoam.aro_decel_mps2" value="{decel:g}"/>
    </vehicle>
{_obstruction(point)}</routes>
"""


def write_scenarios(points: list[TestPoint], folder: Path) -> dict[str, Path]:
    """Build the network and write every point's files under ``folder``; point id -> sumocfg."""
    folder.mkdir(parents=True, exist_ok=True)
    offsets, hol = offset_edges(points), lane_change_edges(points)
    net = build_network(_network_sources(folder, offsets, points))
    write_atomic(folder / "protocol_vtypes.add.xml", VTYPES)
    cfgs = {}
    for point in points:
        pid = point.point_id
        k = hol[pid] if point.lane_change else offsets[point.offset_m]
        write_atomic(folder / f"{pid}.rou.xml", _routes(point, k))
        cfg = sumocfg_text(net.name, f"{pid}.rou.xml", "protocol_vtypes.add.xml")
        cfgs[pid] = write_atomic(folder / f"{pid}.sumocfg", cfg)
    return cfgs
