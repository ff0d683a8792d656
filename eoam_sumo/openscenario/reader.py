"""Reading an .xosc: parameters resolved first, catalogs expanded, the subset checked.

As esmini's ScenarioReader: a ``ParameterValueDistribution`` file names its scenario and one
set of values; ``ParameterDeclarations`` are resolved in order (``--param`` values replace the
declared ones); every attribute's ``$name`` / ``${expr}`` is resolved; each
``CatalogReference`` is replaced by its catalog entry, resolved with its own declarations and
the reference's ``ParameterAssignments``. Nothing here runs the scenario.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from eoam_sumo.errors import InputError
from eoam_sumo.openscenario.expressions import ExpressionError, format_value, substitute
from eoam_sumo.openscenario.subset import check_subset
from eoam_sumo.openscenario.xmltree import Node, parse, root_tag

UNRESOLVED = ("ParameterDeclarations", "ParameterValueDistribution")
# attributes nothing refers to, kept as written (esmini's files build a condition's name
# with a string concatenation, ``${Name + _ + $Value}``, outside the standard's expressions)
UNUSED = {("Condition", "name")}


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
        _distributed_declared(root, chosen, dist, path)
    if root.find("Storyboard") is None:
        raise InputError(f"{path}: not an OpenSCENARIO scenario (no <Storyboard>)")
    values = declared_values(root.find("ParameterDeclarations"), given, path, check_types=True)
    catalogs = _catalog_dirs(root, values, path.parent)
    tree = _resolve(root, values, catalogs, scoped=True)
    check_subset(tree)
    return Scenario(path, values, tree, _road(tree, path))


# the suffixes of OpenSCENARIO files: a scenario, a parameter variation file (esmini's .xosp)
SUFFIXES = (".xosc", ".xosp")


def is_openscenario(path: Path) -> bool:
    """Whether ``path`` is an OpenSCENARIO file: by its suffix (.xosc, .xosp), else by its
    root element ``<OpenSCENARIO>`` (whatever the file is called)."""
    return Path(path).suffix.lower() in SUFFIXES or root_tag(path) == "OpenSCENARIO"


def _distributed_declared(root: Node, chosen: dict[str, str], dist: Node, path: Path) -> None:
    """Every parameter a distribution sets is declared by its scenario."""
    decls = root.find("ParameterDeclarations")
    names = {d.get("name") for d in ([] if decls is None else decls.children)}
    for name in chosen:
        if name not in names:
            raise InputError(
                f"{dist.where()}: sets parameter {name}, which {path} does not declare"
            )


def declared_values(
    decls: Node | None,
    given: dict[str, str],
    path: Path,
    outer: dict[str, str] | None = None,
    check_types: bool = False,
) -> dict[str, str]:
    """Parameter name -> value: declarations in order, ``given`` replacing declared values
    (``outer``: the values of the enclosing scope, which a declaration's value may use;
    ``check_types``: each given value must be of its declared type, :func:`typed_value`)."""
    values: dict[str, str] = {}
    for decl in [] if decls is None else decls.findall("ParameterDeclaration"):
        name = decl.need("name")
        text = given[name] if name in given else decl.need("value")
        value = _finite(_sub(text, {**(outer or {}), **values}, decl), name, decl)
        values[name] = typed_value(value, decl, checked=check_types and name in given)
    unknown = sorted(set(given) - set(values))
    if unknown:
        raise InputError(f"--param {unknown[0]}: no such parameter declared in {path}")
    return values


# xsd:boolean's lexical forms (OpenSCENARIO's ParameterType boolean), as the words compared
BOOLEANS = {"true": "true", "false": "false", "1": "true", "0": "false"}
# ParameterType (OpenSCENARIO 1.0 "integer", 1.1+ "int") -> what a value of it must be
TYPES = {"integer": "an integer", "int": "an integer", "unsignedInt": "an integer >= 0",
         "unsignedShort": "an integer in [0, 65535]", "double": "a number",
         "boolean": "a boolean (true, false, 1 or 0)"}  # fmt: skip


def typed_value(text: str, decl: Node, checked: bool = True) -> str:
    """``text`` as a value of the declaration's ``parameterType`` (a boolean written
    ``true``/``false``, so that 1 and true compare equal); ``checked``: InputError in one
    line naming the parameter when it is not of that type (a value given by ``--param`` or
    a distribution)."""
    kind = decl.get("parameterType", "string")
    if kind == "boolean" and text.strip() in BOOLEANS:
        return BOOLEANS[text.strip()]
    if not checked or kind not in TYPES or _of_type(text.strip(), kind):
        return text
    raise InputError(f"{decl.where()}: parameter {decl.get('name')} = {text!r} is not "
                     f"{TYPES[kind]}, its declared parameterType {kind}")  # fmt: skip


def _of_type(text: str, kind: str) -> bool:
    if kind == "boolean":
        return False  # not one of BOOLEANS
    try:
        value = float(text)
    except ValueError:
        return False
    if kind == "double":
        return True
    whole = value.is_integer()  # 30.0 too: a range's or a TOML sweep's value
    low, top = {"unsignedInt": (0, 2**32 - 1), "unsignedShort": (0, 65535)}.get(
        kind, (-(2**31), 2**31 - 1)
    )
    return whole and low <= value <= top


def _finite(text: str, name: str, decl: Node) -> str:
    """``text`` unless it is a number that is not finite (float() reads "nan", "inf")."""
    try:
        bad = not math.isfinite(float(text))
    except ValueError:
        bad = False
    if bad:
        raise InputError(f"{decl.where()}: parameter {name} = {text!r} is not a finite number")
    return text


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
    det = deterministic(dist)
    chosen: dict[str, str] = {}
    for node in det.children:
        names = {node.get("parameterName")} | {
            a.get("parameterRef") for a in node.iter() if a.tag == "ParameterAssignment"
        }
        if names - {None} <= given:
            continue
        chosen |= _one_set(node)
    return (path.parent / scen.need("filepath")).resolve(), chosen


def deterministic(dist: Node) -> Node:
    """The ``Deterministic`` distribution of a ``ParameterValueDistribution`` (the only
    kind supported; the standard requires one, deterministic or stochastic)."""
    others = [c for c in dist.children if c.tag != "ScenarioFile"]
    if not others:
        raise InputError(f"{dist.where()}: no distribution (Deterministic) beside <ScenarioFile>")
    det = dist.find("Deterministic")
    if det is None or len(others) != 1:
        other = next((c for c in others if c.tag != "Deterministic"), others[-1])
        raise InputError(f"{other.where()}: only a Deterministic distribution is supported")
    return det


def distribution_range(kind: Node) -> tuple[float, float, int]:
    """(lower limit, step, number of values) of a ``DistributionRange``: its values are
    ``range_value(lower, step, k)``, k from 0; InputError when it has no Range or none."""
    rng = kind.find("Range")
    if rng is None:
        raise InputError(f"{kind.where()}: a DistributionRange needs a Range")
    lo, hi, step = rng.num("lowerLimit"), rng.num("upperLimit"), kind.num("stepWidth")
    if step <= 0 or hi < lo:
        raise InputError(f"{kind.where()}: range {lo:g}..{hi:g} by {step:g} is empty")
    return lo, step, int((hi - lo) / step + 1e-9) + 1


def range_value(lo: float, step: float, k: int) -> str:
    """The k-th value of a range as an attribute's text, rounded to 12 decimals (lo + k step
    carries the binary fractions' error: 0.1 + 2 x 0.1 = 0.30000000000000004)."""
    return format_value(round(lo + k * step, 12))


def _one_set(node: Node) -> dict[str, str]:
    """The values of a distribution with exactly one value (set)."""
    sets = [n for n in node.iter() if n.tag in ("Element", "ParameterValueSet", "Range")]
    kind = node.children[0] if node.children else node
    if len(sets) == 1 and kind.tag == "DistributionRange":
        lo, step, count = distribution_range(kind)
        if count == 1:
            return {node.need("parameterName"): range_value(lo, step, 0)}
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


def _resolve(
    node: Node, values: dict[str, str], catalogs: list[Path], via: str = "", scoped: bool = False
) -> Node:
    """A copy of ``node`` with attributes resolved and catalog references expanded. A node's
    own ``ParameterDeclarations`` (a Story's, a Maneuver's...) add to the values in scope
    for it and its descendants (OpenSCENARIO 1.2 sec. 8.4.1); ``scoped``: already added (the
    scenario's and a catalog entry's)."""
    if node.tag == "CatalogReference":
        return _expand(node, values, catalogs)
    decls = node.find("ParameterDeclarations")
    if decls is not None and not scoped:
        values = {**values, **declared_values(decls, {}, node.file, values)}
    attrib = {
        k: v if (node.tag, k) in UNUSED else _sub(v, values, node) for k, v in node.attrib.items()
    }
    kids = [c if c.tag in UNRESOLVED else _resolve(c, values, catalogs, via) for c in node.children]
    scope = None
    if node.tag == "ParameterCondition":  # sec. 8.4.1: its scope; a boolean's 1/0 as words
        scope, have = values, values.get(attrib.get("parameterRef", ""))
        if have in ("true", "false") and attrib.get("value", "").strip() in BOOLEANS:
            attrib["value"] = BOOLEANS[attrib["value"].strip()]
    return Node(node.tag, attrib, node.file, node.line, kids, via, scope)


def _expand(ref: Node, values: dict[str, str], catalogs: list[Path]) -> Node:
    """The catalog entry a reference names, resolved with its assignments."""
    cat, entry = (_sub(ref.need(k), values, ref) for k in ("catalogName", "entryName"))
    found = find_entry(cat, entry, catalogs)
    if found is None:
        raise InputError(f"{ref.where()}: catalog entry {cat}/{entry} not found")
    decls = found.find("ParameterDeclarations")
    names = {d.need("name") for d in ([] if decls is None else decls.children)}
    assigned = {}
    for a in (ref.find("ParameterAssignments") or _EMPTY).children:
        name = a.need("parameterRef").removeprefix("$")  # esmini's files write "$Name"
        if name not in names:
            raise InputError(f"{a.where()}: catalog entry {cat}/{entry} declares no parameter "
                             f"{name} ({found.file})")  # fmt: skip
        assigned[name] = _sub(a.need("value"), values, a)
    own = declared_values(decls, assigned, found.file)
    return _resolve(found, own, catalogs, f" (from {ref.where()})", scoped=True)


_EMPTY = Node("ParameterAssignments", {}, Path("-"), 0)


def find_entry(catalog: str, entry: str, dirs: list[Path]) -> Node | None:
    """Entry ``entry`` of the catalog named ``catalog`` in any of ``dirs``: a ``<Catalog>``
    of that name, else one in a file of that name (as esmini finds its own catalogs, whose
    ``EnvironmentCatalog.xosc`` declares ``<Catalog name="VehicleCatalog">``)."""
    files = [f for d in dirs if d.is_dir() for f in sorted(d.glob("*.xosc"))]
    for by_file in (False, True):
        for f in files:
            cat = parse(f).find("Catalog")
            name = f.stem if by_file else (None if cat is None else cat.get("name"))
            if cat is None or name != catalog:
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
