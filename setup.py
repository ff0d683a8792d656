"""Build of eoam-sumo: the modules of the co-simulation step compiled to C with mypyc.

mypyc (part of mypy) compiles the typed Python of the modules in ``COMPILED`` to C extension
modules, which Python imports in place of the sources: the same code and arithmetic (no fast
math), about a quarter less time a step (docs/performance.md). Everything else stays Python.

Without mypyc, without a working C compiler, or when compiling fails, the package installs as
pure Python and a warning says so; so does ``EOAM_SUMO_PURE=1`` at install (and at run time:
``eoam_sumo/__init__.py``). Metadata and dependencies are in pyproject.toml.
"""

import hashlib
import json
import os
import sysconfig
import warnings
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent

#: The modules compiled: what the step loop runs at every step (sensing, decision, control,
#: contact, observers, the SUMO exchange), none of the set-up, files or plotting.
COMPILED = [
    "eoam_sumo/eoam.py",
    "eoam_sumo/eoam_messages.py",
    "eoam_sumo/control/escape.py",
    "eoam_sumo/control/longitudinal.py",
    "eoam_sumo/control/paths.py",
    "eoam_sumo/control/steering.py",
    "eoam_sumo/decision/dmm.py",
    "eoam_sumo/decision/modes.py",
    "eoam_sumo/decision/obstacle.py",
    "eoam_sumo/decision/oncoming.py",
    "eoam_sumo/decision/policy.py",
    "eoam_sumo/sensing/automotive.py",
    "eoam_sumo/sensing/friction.py",
    "eoam_sumo/sensing/next_lane.py",
    "eoam_sumo/sensing/tracker.py",
    "eoam_sumo/sensing/v2x.py",
    "eoam_sumo/sim/bodies.py",
    "eoam_sumo/sim/coasting.py",
    "eoam_sumo/sim/cosim.py",
    "eoam_sumo/sim/facts.py",
    "eoam_sumo/sim/geometry.py",
    "eoam_sumo/sim/lanes.py",
    "eoam_sumo/sim/margins.py",
    "eoam_sumo/sim/observers.py",
    "eoam_sumo/sim/outcome.py",
    "eoam_sumo/sim/radar.py",
    "eoam_sumo/sim/roadframe.py",
    "eoam_sumo/sim/settings.py",
    "eoam_sumo/sim/severity.py",
    "eoam_sumo/sim/trafficlog.py",
    "eoam_sumo/sim/verdict.py",
    "eoam_sumo/sim/session/calls.py",
    "eoam_sumo/sim/session/scripts.py",
    "eoam_sumo/sim/session/session.py",
    "eoam_sumo/sim/session/tracking.py",
]
#: The extension holding the compiled code (the per-module extensions import it).
GROUP = "eoam_sumo._compiled"
#: What a build compiled, beside the extensions: source path -> SHA-256, and why it failed
#: (``eoam_sumo.native`` reads it when the package is imported).
MANIFEST = "compiled_sources.json"


class BuildCompiled(build_ext):
    """build_ext with the mypyc extensions, or none (pure Python) when they cannot be built."""

    failed: str | None = None  # why the build is pure Python, if it failed

    def _pure(self, reason: str, failed: bool = True) -> None:
        warnings.warn(
            f"eoam-sumo installs as pure Python ({reason}): results are the same, "
            "the step loop slower",
            RuntimeWarning,
            stacklevel=2,
        )
        self.extensions = []
        if failed:
            self.failed = reason

    def finalize_options(self) -> None:
        self.distribution.ext_modules = self._extensions()
        super().finalize_options()

    def _extensions(self) -> list[Extension]:
        if os.environ.get("EOAM_SUMO_PURE"):
            self._pure("EOAM_SUMO_PURE is set", failed=False)
            return []
        try:
            from mypyc.build import mypycify
        except ImportError:
            self._pure("mypyc is not installed")
            return []
        os.chdir(ROOT)  # mypyc names modules by their paths
        try:
            return mypycify(COMPILED, opt_level="3", group_name=GROUP)
        except (SystemExit, Exception) as err:  # noqa: BLE001 - any failure: pure Python
            self._pure(f"mypyc failed: {err!r}")
            return []

    def run(self) -> None:
        in_source = self.inplace or getattr(self, "editable_mode", False)
        package = ROOT / "eoam_sumo" if in_source else Path(self.build_lib) / "eoam_sumo"
        (package / MANIFEST).unlink(missing_ok=True)  # written again once the build is done
        if in_source:  # no extension module of an earlier build left to shadow its source
            for ext in package.rglob(f"*{sysconfig.get_config_var('EXT_SUFFIX')}"):
                ext.unlink()
        if self.extensions:
            try:
                super().run()
            except Exception as err:  # noqa: BLE001 - no compiler or a failed compile: pure
                self._pure(f"compiling failed: {err}")
        record: dict = {"compiled": {}, "failed": self.failed}
        if self.extensions:
            record["compiled"] = {
                rel: hashlib.sha256((ROOT / rel).read_bytes()).hexdigest() for rel in COMPILED
            }
        if self.extensions or self.failed:
            package.mkdir(parents=True, exist_ok=True)
            (package / MANIFEST).write_text(json.dumps(record, indent=1) + "\n")


# a placeholder, so that setuptools runs build_ext, which puts the real extensions in its place
setup(
    ext_modules=[Extension(f"{GROUP}_placeholder", sources=[])],
    cmdclass={"build_ext": BuildCompiled},
)
