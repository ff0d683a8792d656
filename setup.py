"""Build of eoam-sumo: optionally, the modules of the co-simulation step compiled with mypyc.

Pure Python unless ``EOAM_SUMO_COMPILE=1`` is set when installing or building. Then mypyc (part
of mypy) compiles the typed Python of the modules in ``COMPILED`` to C extension modules, which
Python imports in place of their sources: the same code and arithmetic (no fast math), the step
loop faster. A compile that fails then fails the build: nothing falls back silently. The
package itself never knows which it runs (docs/performance.md, "The compiled build").
Metadata and dependencies are in pyproject.toml.
"""

import os
from pathlib import Path

from setuptools import setup

ROOT = Path(__file__).resolve().parent
COMPILE_ENV = "EOAM_SUMO_COMPILE"

#: The modules compiled: what the step loop runs at every step (sensing, decision, control,
#: contact, observers, the SUMO exchange), none of the set-up, files or plotting.
COMPILED = [
    "eoam_sumo/eoam/controller.py",
    "eoam_sumo/eoam/decide.py",
    "eoam_sumo/eoam/lateral.py",
    "eoam_sumo/eoam/longitudinal.py",
    "eoam_sumo/eoam/parts.py",
    "eoam_sumo/eoam/perceive.py",
    "eoam_sumo/eoam/shifts.py",
    "eoam_sumo/eoam/sides.py",
    "eoam_sumo/eoam/state.py",
    "eoam_sumo/eoam/strategies.py",
    "eoam_sumo/eoam/transitions.py",
    "eoam_sumo/eoam_messages.py",
    "eoam_sumo/control/brake_split.py",
    "eoam_sumo/control/longitudinal.py",
    "eoam_sumo/control/steering.py",
    "eoam_sumo/decision/dmm.py",
    "eoam_sumo/decision/modes.py",
    "eoam_sumo/decision/obstacle.py",
    "eoam_sumo/decision/oncoming.py",
    "eoam_sumo/decision/policy.py",
    "eoam_sumo/manoeuvre/angles.py",
    "eoam_sumo/manoeuvre/lateral_state.py",
    "eoam_sumo/manoeuvre/min_time_shift.py",
    "eoam_sumo/manoeuvre/path_reference.py",
    "eoam_sumo/manoeuvre/points.py",
    "eoam_sumo/manoeuvre/quintic_shift.py",
    "eoam_sumo/sensing/automotive.py",
    "eoam_sumo/sensing/friction.py",
    "eoam_sumo/sensing/next_lane.py",
    "eoam_sumo/sensing/tracker.py",
    "eoam_sumo/sensing/v2x.py",
    "eoam_sumo/world/bodies.py",
    "eoam_sumo/sensing/coasting.py",
    "eoam_sumo/sim/cosim.py",
    "eoam_sumo/sim/facts.py",
    "eoam_sumo/sim/interpolation.py",
    "eoam_sumo/world/geometry.py",
    "eoam_sumo/world/lanes.py",
    "eoam_sumo/sim/margins.py",
    "eoam_sumo/sim/observers.py",
    "eoam_sumo/sim/outcome.py",
    "eoam_sumo/sensing/radar.py",
    "eoam_sumo/sim/roadframe.py",
    "eoam_sumo/sim/runlog.py",
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


def compiled_extensions() -> list:
    """The mypyc extension modules when ``EOAM_SUMO_COMPILE=1``, else none (pure Python)."""
    if os.environ.get(COMPILE_ENV) != "1":
        return []
    from mypyc.build import mypycify

    os.chdir(ROOT)  # mypyc names modules by their paths
    return mypycify(COMPILED, opt_level="3", group_name=GROUP)


setup(ext_modules=compiled_extensions())
