"""The ego's route as its files write it, and what that route allows before SUMO starts."""

from __future__ import annotations

from eoam_sumo.errors import InputError
from eoam_sumo.sim.scenario.files import ScenarioFiles
from eoam_sumo.sim.scenario.xmlread import parse_xml


def ego_route_edges(files: ScenarioFiles, ego_id: str = "ego") -> tuple[str, ...] | None:
    """The ego's route edges: its embedded ``<route>`` or the ``<route>`` its ``route=``
    names in the route and additional files; None for a trip or a route not written as
    plain edges (SUMO finds those at insertion)."""
    spec = files.vehicles[ego_id]
    if not spec.routed:
        return None
    named = spec.attrs.get("route")
    if named is None:
        for elem in parse_xml(spec.source, "route file").iter():
            if elem.tag in ("vehicle", "trip") and elem.get("id") == ego_id:
                inner = elem.find("route")
                return _edges(inner.get("edges") if inner is not None else None)
        return None
    for path in files.route_files + files.additional_files:
        for elem in parse_xml(path, "route file").iter("route"):
            if elem.get("id") == named:
                return _edges(elem.get("edges"))
    return None


def _edges(text: str | None) -> tuple[str, ...] | None:
    return tuple(text.split()) if text and text.split() else None


def check_oncoming_road(files: ScenarioFiles, ego_id: str = "ego") -> None:
    """Refuse (InputError naming the network) an oncoming car on an ego route none of whose
    edges has a lane of the other direction beside it (``opposite_lanes``), the check the
    run makes when it inserts the car; a route not known before SUMO routes it passes."""
    edges = ego_route_edges(files, ego_id)
    if edges is None:
        return
    beside = {lane.rsplit("_", 1)[0] for lane in files.opposite_lanes}
    if beside.isdisjoint(edges):
        names = ", ".join(f"'{e}'" for e in edges)
        raise InputError(
            f"{files.net_file}: no oncoming car (--oncoming-m, oncoming_start_m): the ego's "
            f"road is one-way, no lane of the other direction lies beside its route (edges "
            f"{names})"
        )
