"""The package's layers: what each package may import, checked on every import of the sources
(imports inside functions included), and the same table in docs/architecture.md.

A package sits above the ones it may import; none imports one above it. The core (``params``
to ``eoam``) imports no SUMO, pandas or matplotlib. The standard library is always allowed.
"""

from __future__ import annotations

import ast
import re
import sys
from pathlib import Path

import pytest

import eoam_sumo

PACKAGE = Path(eoam_sumo.__file__).resolve().parent
ARCHITECTURE = PACKAGE.parent / "docs" / "architecture.md"
EVERYTHING = "*"

#: package -> (packages of eoam_sumo it may import, third-party top-level modules it may import)
RULES: dict[str, tuple[set[str], set[str]]] = {
    "errors": (set(), set()),
    "colours": (set(), set()),
    "params": (set(), set()),
    "fileio": ({"errors"}, set()),
    "outputs": ({"errors", "fileio"}, set()),
    "textfiles": ({"errors"}, set()),
    "seeds": ({"errors"}, set()),
    "arguments": ({"params"}, set()),
    "vehicle_files": ({"params", "errors", "textfiles"}, set()),
    "sampling": ({"errors", "seeds"}, {"numpy"}),
    "plant": ({"params"}, {"numpy", "casadi"}),
    "manoeuvre": ({"params"}, {"numpy", "scipy"}),
    "offline": (
        {"params", "errors", "fileio", "textfiles", "plant", "manoeuvre"},
        {"numpy", "scipy", "casadi", "tqdm"},
    ),
    "control": ({"params", "manoeuvre"}, {"numpy", "mypy_extensions"}),
    "eoam_messages": (set(), set()),
    "decision": ({"params", "manoeuvre", "eoam_messages"}, {"numpy", "mypy_extensions"}),
    "eoam_settings": ({"params", "control", "decision"}, set()),
    "eoam": (
        {"params", "manoeuvre", "control", "decision", "eoam_messages", "eoam_settings"},
        set(),
    ),
    "drivers": (
        {"params", "control", "decision", "eoam", "eoam_messages", "eoam_settings"},
        {"mypy_extensions"},
    ),
    "world": (set(), {"numpy", "mypy_extensions"}),
    "sensing": (
        {"params", "errors", "manoeuvre", "eoam_messages", "world"},
        {"numpy", "mypy_extensions"},
    ),
    "sim": (
        {
            "params",
            "errors",
            "colours",
            "fileio",
            "plant",
            "offline",
            "eoam",
            "eoam_messages",
            "eoam_settings",
            "drivers",
            "sensing",
            "world",
            "vehicle_files",
        },
        {"numpy", "pandas", "pyarrow", "libsumo", "traci", "sumolib", "sumo", "mypy_extensions"},
    ),
    "matrix": (
        {
            "params",
            "errors",
            "colours",
            "sampling",
            "seeds",
            "textfiles",
            "offline",
            "sensing",
            "sim",
            "drivers",
            "traffic_levels",
            "vehicle_files",
        },
        set(),
    ),
    "batch": (
        {
            "params",
            "errors",
            "colours",
            "fileio",
            "textfiles",
            "sampling",
            "sensing",
            "sim",
            "matrix",
            "outputs",
            "traffic_levels",
            "vehicle_files",
        },
        {"numpy", "pandas", "statsmodels", "dask", "distributed", "tqdm", "pyarrow"},
    ),
    "plotting": (
        {"params", "errors", "colours", "sampling", "offline", "decision", "world", "sim", "batch"},
        {"numpy", "pandas", "matplotlib"},
    ),
    "vehicle_tests": (
        {"params", "errors", "fileio", "arguments", "vehicle_files", "plant", "plotting"},
        {"numpy"},
    ),
    "traffic_scenario": (set(), {"sumolib"}),
    "netbuild": ({"errors"}, {"sumolib", "sumo"}),
    "openscenario": ({"params", "errors", "fileio", "netbuild", "sim", "batch"}, {"sumolib"}),
    "traffic_levels": ({"errors", "seeds", "offline", "netbuild", "outputs"}, {"numpy", "libsumo"}),
    "bench": (
        {
            "params",
            "errors",
            "plant",
            "offline",
            "sensing",
            "sim",
            "batch",
            "outputs",
            "protocols",
            "traffic_scenario",
        },
        {"libsumo", "sumolib"},
    ),
    "protocols": (
        {
            "params",
            "arguments",
            "errors",
            "fileio",
            "outputs",
            "offline",
            "matrix",
            "batch",
            "netbuild",
            "plotting",
            "vehicle_files",
            "sim",
        },
        {"pandas"},
    ),
    "r157": (
        {"errors", "fileio", "netbuild", "outputs", "drivers", "sensing", "sim", "plotting"},
        set(),
    ),
    "cli": ({EVERYTHING}, set()),
    "__main__": ({"cli"}, set()),
}


def _package_of(path: Path) -> str:
    parts = path.relative_to(PACKAGE).with_suffix("").parts
    return parts[0]


def _imported(path: Path) -> set[str]:
    """Top-level module names ``path`` imports (``eoam_sumo.x`` as ``eoam_sumo.x``)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            found.add(node.module)
    return found


def _third_party(top: str) -> bool:
    return top not in sys.stdlib_module_names and top != "__future__"


def _modules() -> list[Path]:
    """Every module of the package but its root ``__init__`` (the version only)."""
    return [p for p in sorted(PACKAGE.rglob("*.py")) if p.parent != PACKAGE or p.stem != "__init__"]


def _broken_rules(path: Path) -> list[str]:
    package = _package_of(path)
    inside, outside = RULES[package]
    broken = []
    for name in sorted(_imported(path)):
        parts = name.split(".")
        if parts[0] == "eoam_sumo":
            target = parts[1] if len(parts) > 1 else ""
            allowed = not target or target == package or EVERYTHING in inside
            if not (allowed or target in inside):
                broken.append(f"{path.relative_to(PACKAGE.parent)} imports {name}")
        elif _third_party(parts[0]) and parts[0] not in outside and EVERYTHING not in inside:
            broken.append(f"{path.relative_to(PACKAGE.parent)} imports {name}")
    return broken


def test_every_package_has_a_rule():
    packages = {_package_of(p) for p in _modules()}
    assert packages - set(RULES) == set(), "add these packages to RULES and the docs table"


def test_every_import_keeps_to_the_rules():
    broken = [line for p in _modules() for line in _broken_rules(p)]
    assert broken == []


def test_the_rules_have_no_cycle():
    def below(package: str, seen: tuple[str, ...]) -> None:
        for lower in RULES[package][0] - {EVERYTHING}:
            assert lower not in seen, " -> ".join((*seen, lower))
            below(lower, (*seen, lower))

    for package in RULES:
        below(package, (package,))


def test_the_core_imports_no_sumo_pandas_or_matplotlib():
    core = ("params", "plant", "manoeuvre", "offline", "control", "decision", "eoam", "drivers")
    banned = {"libsumo", "traci", "sumolib", "sumo", "pandas", "matplotlib"}
    assert all(not (RULES[p][1] & banned) for p in core)


def _documented() -> dict[str, set[str]]:
    """docs/architecture.md's package table: package -> the names its 'may import' cell shows."""
    table = {}
    for line in ARCHITECTURE.read_text(encoding="utf-8").splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        name = re.fullmatch(r"`(\w+)(?:/|\.py)`", cells[0]) if len(cells) == 3 else None
        if name:
            table[name.group(1)] = set(re.findall(r"`([a-z_*]+)`", cells[2]))
    return table


@pytest.mark.parametrize("package", sorted(RULES))
def test_the_architecture_page_shows_the_rules(package):
    inside, outside = RULES[package]
    assert _documented().get(package) == inside | outside
