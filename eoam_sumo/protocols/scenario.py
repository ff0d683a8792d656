"""Every test point as a SUMO scenario: one shared network, one route file and sumocfg each.

The network (built with netconvert through :mod:`eoam_sumo.netbuild`) is the straight 4 km
two-way road of ``networks/highway`` (ego lane ``E0_0``, centre y = -1.75 m, with the
opposite lane as its neighbour, so the EOAM can change lanes) plus, for every lateral target
offset, a one-lane edge under the ego lane: ``T<k>`` eastbound (the target ahead) and
``H<k>`` westbound (the head-on target), their lane centre at y = -1.75 + offset. SUMO keeps
a vehicle on its lane's centre, so the offset lane places the target at its overlap; the
radar and the contact test see it where it is (geometry, never lane ids).

The target's speed profile is a scripted stop (``eoam.aro_hold_s``, ``eoam.aro_decel_mps2``,
docs/scenarios.md): stationary (departs at 0), constant (holds for the whole run) or braking
at the given deceleration after a hold.
"""

from __future__ import annotations

from pathlib import Path

from eoam_sumo.fileio import write_atomic
from eoam_sumo.netbuild import build_network
from eoam_sumo.protocols.points import GVT_LENGTH_M, GVT_WIDTH_M, TestPoint

ROAD_M = 4000.0
EGO_LANE_Y_M = -1.75
EGO_FRONT_X_M = 100.0
DEPART_S = 1.0
STOPPED_DECEL_MPS2 = 10.0  # a stationary target's script: held at 0 from its departure


def offset_edges(points: list[TestPoint]) -> dict[float, int]:
    """Each distinct target offset -> the index k of its edges ``T<k>``/``H<k>``."""
    return {off: k for k, off in enumerate(sorted({p.offset_m for p in points}))}


def _network_sources(folder: Path, offsets: dict[float, int]) -> Path:
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
                f' spreadType="center"><lane index="0" friction="1.00"/></edge>'
            )
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
     {GVT_LENGTH_M} x {GVT_WIDTH_M} m (vectorgrp/OSC-NCAP-scenarios Vehicles.xosc). -->
<additional>
    <vType id="ego" vClass="passenger" length="4.92" width="1.85" minGap="2.00" maxSpeed="60.00"
           accel="4.00" decel="9.00" emergencyDecel="12.00" sigma="0" speedDev="0"/>
    <vType id="gvt" vClass="passenger" length="{GVT_LENGTH_M}" width="{GVT_WIDTH_M}"
           minGap="1.00" maxSpeed="50.00" accel="2.50" decel="10.00" emergencyDecel="12.00"
           sigma="0" speedDev="0"/>
</additional>
"""

SUMOCFG = """<?xml version="1.0" encoding="UTF-8"?>
<configuration>
    <input>
        <net-file value="{net}"/>
        <route-files value="{routes}"/>
        <additional-files value="{vtypes}"/>
    </input>
    <time><begin value="0"/><end value="600"/><step-length value="0.01"/></time>
    <processing><collision.action value="none"/><time-to-teleport value="-1"/></processing>
    <random_number><seed value="42"/></random_number>
    <report><no-step-log value="true"/></report>
</configuration>
"""


def _routes(point: TestPoint, k: int) -> str:
    """The ego and the target of one point (SUMO places a vehicle by its front bumper)."""
    ego_mps, tgt_mps = point.ego_speed_kmh / 3.6, point.target_speed_kmh / 3.6
    if point.head_on:
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
</routes>
"""


def write_scenarios(points: list[TestPoint], folder: Path) -> dict[str, Path]:
    """Build the network and write every point's files under ``folder``; point id -> sumocfg."""
    folder.mkdir(parents=True, exist_ok=True)
    offsets = offset_edges(points)
    net = build_network(_network_sources(folder, offsets))
    write_atomic(folder / "protocol_vtypes.add.xml", VTYPES)
    cfgs = {}
    for point in points:
        pid = point.point_id
        write_atomic(folder / f"{pid}.rou.xml", _routes(point, offsets[point.offset_m]))
        cfg = SUMOCFG.format(
            net=net.name, routes=f"{pid}.rou.xml", vtypes="protocol_vtypes.add.xml"
        )
        cfgs[pid] = write_atomic(folder / f"{pid}.sumocfg", cfg)
    return cfgs
