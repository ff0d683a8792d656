"""The compiled build (setup.py: mypyc) never runs code older than the sources.

The guard (``eoam_sumo.native``) is exercised on a copy of the package in which one module has
a stand-in extension module that cannot be imported: importing the module fails exactly when
the guard would use the extension.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from importlib import machinery
from pathlib import Path

from eoam_sumo import native

ROOT = Path(__file__).resolve().parents[1]
MODULE = "eoam_sumo.sim.geometry"
SOURCE = "eoam_sumo/sim/geometry.py"


def test_the_compiled_modules_were_built_from_the_sources_as_they_are():
    stale = native.stale_sources()
    assert not stale, (
        f"extension modules not built from {stale} as they are now: rebuild "
        "with 'make' or 'pip install -e .' (or set EOAM_SUMO_PURE=1)"
    )


def _package_copy(tmp_path: Path, recorded_digest: str) -> Path:
    """The package's sources, with a broken extension module for MODULE and a build record
    giving ``recorded_digest`` for its source."""
    shutil.copytree(
        ROOT / "eoam_sumo",
        tmp_path / "eoam_sumo",
        ignore=shutil.ignore_patterns(
            "__pycache__", native.MANIFEST.name, *(f"*{s}" for s in machinery.EXTENSION_SUFFIXES)
        ),
    )
    source = tmp_path / SOURCE
    source.with_suffix(machinery.EXTENSION_SUFFIXES[0]).write_bytes(b"not a shared library")
    (tmp_path / "eoam_sumo" / native.MANIFEST.name).write_text(
        json.dumps({"compiled": {SOURCE: recorded_digest}, "failed": None})
    )
    return tmp_path


def _import(root: Path, pure: bool = False) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k != native.PURE_ENV}
    env["PYTHONPATH"] = str(root)
    if pure:
        env[native.PURE_ENV] = "1"
    code = f"import {MODULE} as m; print(m.__spec__.origin)"
    return subprocess.run(
        [sys.executable, "-W", "always", "-c", code],
        cwd=root,
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )


def test_an_extension_module_built_from_the_source_as_it_is_is_used(tmp_path):
    root = _package_copy(tmp_path, native.source_digest(ROOT / SOURCE))
    assert native.stale_sources(root / "eoam_sumo") == []
    run = _import(root)
    assert run.returncode != 0 and "ImportError" in run.stderr  # the stand-in was loaded


def test_an_edited_source_runs_instead_of_its_old_build_with_a_warning(tmp_path):
    root = _package_copy(tmp_path, native.source_digest(ROOT / SOURCE))
    with open(root / SOURCE, "a") as f:
        f.write("# edited after the build\n")
    assert native.stale_sources(root / "eoam_sumo") == [SOURCE]
    run = _import(root)
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == str(root / SOURCE)
    assert "RuntimeWarning" in run.stderr and SOURCE in run.stderr and "rebuild" in run.stderr


def test_an_extension_module_with_no_build_record_is_not_used(tmp_path):
    root = _package_copy(tmp_path, "0" * 64)
    (root / "eoam_sumo" / native.MANIFEST.name).unlink()
    assert native.stale_sources(root / "eoam_sumo") == [SOURCE]
    run = _import(root)
    assert run.returncode == 0 and run.stdout.strip() == str(root / SOURCE), run.stderr


def test_an_install_whose_compiling_failed_says_so(tmp_path):
    root = _package_copy(tmp_path, "0" * 64)
    for ext in (root / "eoam_sumo").rglob(f"*{machinery.EXTENSION_SUFFIXES[0]}"):
        ext.unlink()
    (root / "eoam_sumo" / native.MANIFEST.name).write_text(
        json.dumps({"compiled": {}, "failed": "no C compiler"})
    )
    run = _import(root)
    assert run.returncode == 0 and run.stdout.strip() == str(root / SOURCE), run.stderr
    assert "RuntimeWarning" in run.stderr and "no C compiler" in run.stderr


def test_eoam_sumo_pure_runs_the_sources_without_a_warning(tmp_path):
    root = _package_copy(tmp_path, native.source_digest(ROOT / SOURCE))
    run = _import(root, pure=True)
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == str(root / SOURCE)
    assert "Warning" not in run.stderr


def test_the_makefile_reinstalls_when_a_compiled_source_changes():
    compiled = [
        line.strip().strip('",')
        for line in (ROOT / "setup.py").read_text().splitlines()
        if line.strip().startswith('"eoam_sumo/')
    ]
    assert len(compiled) > 20 and all((ROOT / rel).is_file() for rel in compiled)
    run = subprocess.run(
        ["make", "-s", "-p", "-n", "-f", "Makefile", "clean"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=True,
    )
    line = next(x for x in run.stdout.splitlines() if x.startswith("COMPILED_SOURCES :="))
    assert line.split(":=", 1)[1].split() == compiled
