"""The package does not know how it was built: importing it changes no import machinery, and
the compiled build (setup.py, ``EOAM_SUMO_COMPILE=1``) names modules that exist."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_importing_the_package_leaves_the_import_machinery_as_it_was():
    code = (
        "import sys; before = list(sys.meta_path), list(sys.path_hooks); "
        "import eoam_sumo, eoam_sumo.sim.cosim; "
        "print(before == (list(sys.meta_path), list(sys.path_hooks)))"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=True
    )
    assert out.stdout.strip() == "True", out.stderr


def _compiled_list() -> list[str]:
    tree = ast.parse((ROOT / "setup.py").read_text())
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(
            isinstance(t, ast.Name) and t.id == "COMPILED" for t in node.targets
        ):
            return ast.literal_eval(node.value)
    raise AssertionError("setup.py has no COMPILED list")


def test_the_compiled_build_names_modules_of_the_package():
    names = _compiled_list()
    assert names and len(names) == len(set(names))
    missing = [n for n in names if not (ROOT / n).is_file() or not n.startswith("eoam_sumo/")]
    assert not missing, missing
