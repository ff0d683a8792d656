"""A scenario's files: the ``.sumocfg`` and what it names, checked before SUMO sees them."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

from eoam_sumo.errors import InputError
from eoam_sumo.sim.scenario.network import read_net
from eoam_sumo.sim.scenario.xmlread import parse_xml


@dataclass(frozen=True)
class VehicleSpec:
    """A ``<vehicle>``/``<trip>`` as written in a route or additional file."""

    vid: str
    source: Path
    attrs: dict
    params: dict
    routed: bool = True  # False for a trip (from/to, no route): SUMO routes it at insertion


@dataclass(frozen=True)
class ScenarioFiles:
    """The checked files of a ``.sumocfg`` and what the session needs from them."""

    cfg: Path
    net_file: Path
    route_files: tuple[Path, ...]
    additional_files: tuple[Path, ...]
    vehicles: dict  # vid -> VehicleSpec
    opposite_lanes: dict  # lane id -> id of its <neigh> (opposite-direction) lane
    options: dict = field(default_factory=dict)  # option name -> value as the sumocfg sets it
    edge_lanes: dict = field(default_factory=dict)  # normal edge -> (lane id, index, friction)s


def _option_files(root: ET.Element, cfg: Path, option: str) -> tuple[Path, ...]:
    files = []
    for elem in root.iter(option):
        value = elem.get("value", "")
        files += [cfg.parent / name.strip() for name in value.split(",") if name.strip()]
    return tuple(files)


def _options(root: ET.Element) -> dict:
    """Option name -> value of every option element (``<collision.action value=.../>``)."""
    return {e.tag: e.get("value") for e in root.iter() if e is not root and "value" in e.attrib}


def check_scenario(cfg: Path, ego_id: str = "ego") -> ScenarioFiles:
    """Check a ``.sumocfg`` and its files with ElementTree before SUMO sees them.

    Raises InputError naming the file for a missing or malformed file, a config without a
    net-file, or no vehicle ``ego_id`` in its route and additional files (a flow of that id
    cannot be the ego).
    """
    cfg = Path(cfg)
    root = parse_xml(cfg, "sumocfg")
    nets = _option_files(root, cfg, "net-file")
    if len(nets) != 1:
        raise InputError(f"{cfg}: needs exactly one <net-file value=...>, found {len(nets)}")
    opposite, edge_lanes = read_net(nets[0])
    routes = _option_files(root, cfg, "route-files")
    additionals = _option_files(root, cfg, "additional-files")
    vehicles, flows = _vehicles(routes, additionals)
    if ego_id not in vehicles:
        if ego_id in flows:
            raise InputError(
                f"{flows[ego_id]}: '{ego_id}' is a <flow>: a flow cannot be the ego (SUMO "
                f"makes vehicles '{ego_id}.0', '{ego_id}.1', ... of it); write the ego as one "
                "<vehicle> or <trip>"
            )
        searched = ", ".join(p.name for p in routes + additionals) or "no route files"
        raise InputError(
            f"{cfg}: no vehicle '{ego_id}' in its route or additional files ({searched})"
        )
    options = _options(root)
    _check_end_after_departure(cfg, options, vehicles[ego_id])
    return ScenarioFiles(cfg, nets[0], routes, additionals, vehicles, opposite, options, edge_lanes)


def _seconds(text: str | None) -> float | None:
    """A time option or ``depart`` in seconds; None if absent or not a plain number."""
    try:
        value = float(text) if text is not None else math.nan
    except ValueError:
        return None
    return value if math.isfinite(value) else None


def _check_end_after_departure(cfg: Path, options: dict, ego: VehicleSpec) -> None:
    """Refuse a sumocfg whose ``end`` (>= 0; SUMO's -1 is none) comes before the ego
    departs, as the session refuses a ``begin`` after it: InputError naming both times."""
    end_s, depart_s = _seconds(options.get("end")), _seconds(ego.attrs.get("depart", "0"))
    if end_s is None or depart_s is None or end_s < 0.0 or end_s >= depart_s:
        return
    raise InputError(
        f"{cfg}: the simulation ends at {end_s:g} s (<end>), before vehicle '{ego.vid}' "
        f"departs ({depart_s:g} s, {ego.source.name})"
    )


def _vehicles(
    routes: tuple[Path, ...], additionals: tuple[Path, ...]
) -> tuple[dict[str, VehicleSpec], dict[str, Path]]:
    """(vid -> VehicleSpec of every ``<vehicle>`` and ``<trip>``, flow id -> its file) of the
    route and additional files."""
    vehicles, flows = {}, {}
    for path, what in [(p, "route file") for p in routes] + [
        (p, "additional file") for p in additionals
    ]:
        for elem in parse_xml(path, what).iter():
            vid = elem.get("id")
            if vid is None:
                continue
            if elem.tag == "flow":
                flows[vid] = path
            elif elem.tag in ("vehicle", "trip"):
                params = {p.get("key"): p.get("value") for p in elem.findall("param")}
                routed = elem.tag == "vehicle" and (
                    "route" in elem.attrib or elem.find("route") is not None
                )
                vehicles[vid] = VehicleSpec(vid, path, dict(elem.attrib), params, routed)
    return vehicles, flows


def float_attr(spec: VehicleSpec, key: str, text: str) -> float:
    """A vehicle's attribute or parameter as a finite float; InputError naming the file."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise InputError(f"{spec.source}: vehicle '{spec.vid}' {key}={text!r} is not a number")
    return value
