"""The cases of an .xosc batch: a ``ParameterValueDistribution`` file's deterministic
distributions, or a TOML matrix's ``[sweep]`` of the scenario's parameters; cases outside a
parameter's ``ConstraintGroup``s are left out (the ALKS variation files expect a generator to
discard them: their ranges cross).

Deterministic distributions (OpenSCENARIO 1.2 sec. 9.2): ``DistributionSet`` (its
``Element`` values), ``DistributionRange`` (lower to upper limit by ``stepWidth``, both
ends included), ``ValueSetDistribution`` (its ``ParameterValueSet``s); every combination
across the distributions (a cartesian product). Stochastic distributions are refused.
"""

from __future__ import annotations

import itertools
import tomllib
from dataclasses import dataclass
from pathlib import Path

from eoam_sumo.errors import InputError
from eoam_sumo.openscenario.conditions import RULES
from eoam_sumo.openscenario.expressions import ExpressionError, format_value, substitute
from eoam_sumo.openscenario.reader import (
    declared_values,
    deterministic,
    distribution_range,
    is_openscenario,
    range_value,
)
from eoam_sumo.openscenario.xmltree import Node, parse
from eoam_sumo.params import MU_MAX
from eoam_sumo.sim.settings import MAX_TIME_LIMIT_S

MAX_CASES = 100_000
SCENARIO_KEYS = ("xosc", "system", "mu", "max_time_s")


@dataclass(frozen=True)
class XoscBatch:
    """The scenario, its cases (parameter values), those left out by constraints, options."""

    scenario: Path
    cases: list[dict[str, str]]
    left_out: int
    system: str = "eoam"
    mu: float | None = None
    max_time_s: float | None = None


def is_xosc_batch(path: Path) -> bool:
    """An OpenSCENARIO file (.xosc, .xosp, or an ``<OpenSCENARIO>`` root), or a TOML matrix
    whose ``[scenario]`` names an ``xosc``."""
    if is_openscenario(path):
        return True
    try:
        with Path(path).open("rb") as fh:
            doc = tomllib.load(fh)
    except (OSError, ValueError):  # malformed TOML, not UTF-8
        return False  # the matrix reader says what is wrong with it
    return isinstance(doc.get("scenario"), dict) and "xosc" in doc["scenario"]


def load_batch(path: Path) -> XoscBatch:
    """The batch of ``path`` (a distribution file or a TOML matrix); InputError in one line."""
    path = Path(path)
    if is_openscenario(path):
        scenario, combos = _distribution_cases(path)
        return _kept(XoscBatch(scenario, combos, 0))
    with path.open("rb") as fh:
        doc = tomllib.load(fh)
    scen = doc["scenario"]
    unknown = sorted(set(scen) - set(SCENARIO_KEYS)) + sorted(set(doc) - {"scenario", "sweep"})
    if unknown:
        raise InputError(f"{path}: unknown key {unknown[0]!r} (an .xosc matrix takes [scenario] "
                         f"{', '.join(SCENARIO_KEYS)} and [sweep] of its parameters)")  # fmt: skip
    sweep = doc.get("sweep", {})
    if not isinstance(sweep, dict):
        raise InputError(f"{path}: [sweep] must be a table of parameter = [values]")
    for name, values in sweep.items():
        if not isinstance(values, list) or not values:
            raise InputError(f"{path}: [sweep] {name} must be a non-empty list")
    names = list(sweep)
    combos = [
        {n: _text(v) for n, v in zip(names, vals, strict=True)}
        for vals in itertools.product(*(sweep[n] for n in names))
    ]
    xosc = (path.parent / str(scen["xosc"])).resolve()
    if not xosc.is_file():
        raise InputError(f"{path}: [scenario] xosc {xosc} not found")
    if parse(xosc).find("ParameterValueDistribution") is not None:  # the sweep replaces its axes
        xosc, base = _distribution_cases(xosc, set(names))
        combos = [{**b, **c} for b in base for c in combos]
    _check_declared(path, names, xosc)
    system = str(scen.get("system", "eoam"))
    if system not in ("eoam", "aeb"):
        raise InputError(f"{path}: [scenario] system {system!r} must be eoam or aeb")
    mu, max_time = scen.get("mu"), scen.get("max_time_s")
    for key, value, top in (("mu", mu, MU_MAX), ("max_time_s", max_time, MAX_TIME_LIMIT_S)):
        ok = isinstance(value, int | float) and not isinstance(value, bool) and 0 < value <= top
        if value is not None and not ok:
            raise InputError(f"{path}: [scenario] {key} = {value!r} must be in (0, {top:g}]")
    return _kept(XoscBatch(xosc, combos, 0, system, mu, max_time))


def _check_declared(path: Path, names: list[str], xosc: Path) -> None:
    """InputError naming the matrix file and the first ``[sweep]`` name the scenario does not
    declare (it was reported as a ``--param``)."""
    decls = parse(xosc).find("ParameterDeclarations")
    declared = {d.get("name") for d in ([] if decls is None else decls.children)}
    missing = [n for n in names if n not in declared]
    if missing:
        raise InputError(f"{path}: [sweep] {missing[0]}: no such parameter declared in {xosc}")


def _text(value) -> str:
    return (
        format_value(value)
        if isinstance(value, int | float) and not isinstance(value, bool)
        else str(value)
    )


def _distribution_cases(
    path: Path, swept: frozenset | set = frozenset()
) -> tuple[Path, list[dict[str, str]]]:
    """The scenario a distribution file names and its cases (``swept`` names left out)."""
    root = parse(path)
    dist = root.find("ParameterValueDistribution")
    scen = None if dist is None else dist.find("ScenarioFile")
    if dist is None:  # a scenario: one case, its declared values
        return path.resolve(), [{}]
    if scen is None:
        raise InputError(f"{dist.where()}: no <ScenarioFile>")
    det = deterministic(dist)
    axes = [_axis(node) for node in det.children if not _names(node) <= swept]
    combos = [
        dict(kv for part in parts for kv in part.items()) for parts in itertools.product(*axes)
    ]
    return (path.parent / scen.need("filepath")).resolve(), combos


def _names(node: Node) -> set[str]:
    names = {node.get("parameterName")} | {
        a.get("parameterRef") for a in node.iter() if a.tag == "ParameterAssignment"
    }
    return {n for n in names if n}


def _axis(node: Node) -> list[dict[str, str]]:
    """The value sets of one deterministic distribution."""
    if node.tag == "DeterministicMultiParameterDistribution":
        sets = [n for n in node.iter() if n.tag == "ParameterValueSet"]
        return [
            {a.need("parameterRef"): a.need("value") for a in s.findall("ParameterAssignment")}
            for s in sets
        ]
    name = node.need("parameterName")
    kind = node.children[0] if node.children else node
    if kind.tag == "DistributionSet":
        return [{name: e.need("value")} for e in kind.findall("Element")]
    if kind.tag == "DistributionRange":
        lo, step, count = distribution_range(kind)
        if count > MAX_CASES:
            raise InputError(f"{kind.where()}: {count} values is too many")
        return [{name: range_value(lo, step, k)} for k in range(count)]
    raise InputError(f"{kind.where()}: {kind.tag} is not a supported deterministic distribution")


def _kept(batch: XoscBatch) -> XoscBatch:
    """``batch`` without the cases outside the scenario's parameter constraints."""
    if len(batch.cases) > MAX_CASES:
        raise InputError(f"{batch.scenario}: {len(batch.cases)} cases is more than {MAX_CASES}")
    decls = parse(batch.scenario).find("ParameterDeclarations")
    kept = [c for c in batch.cases if within_constraints(decls, c, batch.scenario)]
    return XoscBatch(
        batch.scenario, kept, len(batch.cases) - len(kept), batch.system, batch.mu, batch.max_time_s
    )


def within_constraints(decls: Node | None, given: dict[str, str], path: Path) -> bool:
    """Whether every declared parameter meets one of its ``ConstraintGroup``s (all of that
    group's ``ValueConstraint``s), its values resolved with ``given``."""
    values = declared_values(decls, given, path)
    for decl in [] if decls is None else decls.findall("ParameterDeclaration"):
        groups = decl.findall("ConstraintGroup")
        if groups and not any(_group_holds(g, values[decl.need("name")], values) for g in groups):
            return False
    return True


def _group_holds(group: Node, have: str, values: dict[str, str]) -> bool:
    for c in group.findall("ValueConstraint"):
        try:
            want = substitute(c.need("value"), values)
        except ExpressionError as exc:
            raise InputError(f"{c.where()}: {exc}") from exc
        rule = RULES.get(c.need("rule"))
        try:
            ok = rule is not None and rule(float(have), float(want))
        except ValueError:
            ok = (have == want) == (c.need("rule") != "notEqualTo")
        if not ok:
            return False
    return True
