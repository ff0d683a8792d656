"""Reading an .xosc: parameters resolved first, catalogs expanded, the subset checked.

As esmini's ScenarioReader: a ``ParameterValueDistribution`` file names its scenario and one
set of values; ``ParameterDeclarations`` are resolved in order (``--param`` values replace the
declared ones); every attribute's ``$name`` / ``${expr}`` is resolved; each
``CatalogReference`` is replaced by its catalog entry, resolved with its own declarations and
the reference's ``ParameterAssignments``. Nothing here runs the scenario.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from eoam_sumo.errors import InputError
from eoam_sumo.openscenario.expressions import ExpressionError, substitute
from eoam_sumo.openscenario.subset import check_subset
from eoam_sumo.openscenario.xmltree import Node, parse

UNRESOLVED = ("ParameterDeclarations", "ParameterValueDistribution")


@dataclass(frozen=True)
class Scenario:
    """A resolved scenario: its file, its parameter values, its storyboard tree, its road."""

    path: Path
    parameters: dict[str, str]
    root: Node
    road: Path


def read_scenario(path: Path, overrides: dict[str, str] | None = None) -> Scenario:
    """The scenario of ``path`` (an .xosc or its parameter distribution), checked against the
    subset; InputError naming the element, file and line for anything outside it."""
    path = Path(path)
    root = parse(path)
    given = dict(overrides or {})
    dist = root.find("ParameterValueDistribution")
    if dist is not None:
        path, chosen = _distribution(path, dist, set(given))
        given = {**chosen, **given}
        root = parse(path)
    if root.find("Storyboard") is None:
        raise InputError(f"{path}: not an OpenSCENARIO scenario (no <Storyboard>)")
    values = declared_values(root.find("ParameterDeclarations"), given, path)
    catalogs = _catalog_dirs(root, values, path.parent)
    tree = _resolve(root, values, catalogs)
    check_subset(tree)
    return Scenario(path, values, tree, _road(tree, path))


def declared_values(decls: Node | None, given: dict[str, str], path: Path) -> dict[str, str]:
    """Parameter name -> value: declarations in order, ``given`` replacing declared values."""
    values: dict[str, str] = {}
    for decl in [] if decls is None else decls.findall("ParameterDeclaration"):
        name = decl.need("name")
        text = given[name] if name in given else decl.need("value")
        values[name] = _sub(text, values, decl)
    unknown = sorted(set(given) - set(values))
    if unknown:
        raise InputError(f"--param {unknown[0]}: no such parameter declared in {path}")
    return values


def _sub(text: str, values: dict[str, str], node: Node) -> str:
    try:
        return substitute(text, values)
    except ExpressionError as exc:
        raise InputError(f"{node.where()}: {exc}") from exc


def _distribution(path: Path, dist: Node, given: set[str]) -> tuple[Path, dict[str, str]]:
    """The scenario file and the single set of values a parameter distribution names (a
    parameter given with ``--param`` may have many values there: ``--param`` picks one)."""
    scen = dist.find("ScenarioFile")
    if scen is None:
        raise InputError(f"{dist.where()}: no <ScenarioFile>")
    det = dist.find("Deterministic")
    if det is None or len(dist.children) != 2:
        other = next(c for c in dist.children if c.tag != "ScenarioFile")
        raise InputError(f"{other.where()}: only a Deterministic distribution is supported")
    chosen: dict[str, str] = {}
    for node in det.children:
        names = {node.get("parameterName")} | {
            a.get("parameterRef") for a in node.iter() if a.tag == "ParameterAssignment"
        }
        if names - {None} <= given:
            continue
        chosen |= _one_set(node)
    return (path.parent / scen.need("filepath")).resolve(), chosen


def _one_set(node: Node) -> dict[str, str]:
    """The values of a distribution with exactly one value (set)."""
    sets = [n for n in node.iter() if n.tag in ("Element", "ParameterValueSet", "Range")]
    if len(sets) != 1 or sets[0].tag == "Range":
        raise InputError(
            f"{node.where()}: {node.get('parameterName') or 'this distribution'} has many "
            "values; `run` takes one (give it with --param NAME=VALUE)"
        )
    if node.tag == "DeterministicSingleParameterDistribution" and sets[0].tag == "Element":
        return {node.need("parameterName"): sets[0].need("value")}
    if sets[0].tag == "ParameterValueSet":
        return {
            a.need("parameterRef"): a.need("value") for a in sets[0].findall("ParameterAssignment")
        }
    raise InputError(f"{node.where()}: not a supported distribution")


def _catalog_dirs(root: Node, values: dict[str, str], base: Path) -> list[Path]:
    locations = root.find("CatalogLocations")
    return [
        (base / _sub(d.need("path"), values, d)).resolve()
        for loc in ([] if locations is None else locations.children)
        for d in loc.findall("Directory")
    ]


def _resolve(node: Node, values: dict[str, str], catalogs: list[Path], via: str = "") -> Node:
    """A copy of ``node`` with attributes resolved and catalog references expanded."""
    if node.tag == "CatalogReference":
        return _expand(node, values, catalogs)
    attrib = {k: _sub(v, values, node) for k, v in node.attrib.items()}
    kids = [c if c.tag in UNRESOLVED else _resolve(c, values, catalogs, via) for c in node.children]
    return Node(node.tag, attrib, node.file, node.line, kids, via)


def _expand(ref: Node, values: dict[str, str], catalogs: list[Path]) -> Node:
    """The catalog entry a reference names, resolved with its assignments."""
    cat, entry = (_sub(ref.need(k), values, ref) for k in ("catalogName", "entryName"))
    found = find_entry(cat, entry, catalogs)
    if found is None:
        raise InputError(f"{ref.where()}: catalog entry {cat}/{entry} not found")
    assigned = {
        a.need("parameterRef"): _sub(a.need("value"), values, a)
        for a in (ref.find("ParameterAssignments") or _EMPTY).children
    }
    own = declared_values(found.find("ParameterDeclarations"), assigned, found.file)
    return _resolve(found, own, catalogs, f" (from {ref.where()})")


_EMPTY = Node("ParameterAssignments", {}, Path("-"), 0)


def find_entry(catalog: str, entry: str, dirs: list[Path]) -> Node | None:
    """Entry ``entry`` of the catalog named ``catalog`` in any of ``dirs``."""
    for d in dirs:
        for f in sorted(d.glob("*.xosc")) if d.is_dir() else []:
            cat = parse(f).find("Catalog")
            if cat is None or cat.get("name") != catalog:
                continue
            for e in cat.children:
                if e.get("name") == entry:
                    return e
    return None


def _road(tree: Node, path: Path) -> Path:
    net = tree.find("RoadNetwork")
    logic = None if net is None else net.find("LogicFile")
    if logic is None:
        raise InputError(f"{path}: no <RoadNetwork><LogicFile> (the OpenDRIVE road)")
    road = (path.parent / logic.need("filepath")).resolve()
    if not road.is_file():
        raise InputError(f"{logic.where()}: road file {road} not found")
    return road
