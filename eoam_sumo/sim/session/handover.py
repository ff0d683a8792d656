"""The time before the ego departs, simulated at the scenario's own step length.

A sumocfg that asks for a ``step-length`` longer than the co-simulation's step is run by SUMO at
that step up to the handover time (the last multiple of it, counted from ``begin``, at or
before the ego's departure and any scripted stop's vehicle's: those depart after it), its
state saved
there (``simulation.saveState`` at full precision, random number generators and persons
included) and loaded into SUMO restarted at the co-simulation's step (``load`` with
``--load-state``), which steps on to the departure. The state at the handover is the one the
scenario's own step length produces (vehicle positions, speeds, angles and lanes equal to a
plain SUMO run at that step, checked by the tests). sumo-gui hands over the same way (``load``
restarts the simulation in its window), so a run watched in it is the run without it.

No handover (the whole run at the co-simulation's step) when the sumocfg's step is not longer
(or not given: SUMO's default of 1 s is not the scenario asking for it), when the user's extra
options set the step length, or when the sumocfg writes any output file or log (SUMO's
restart would start those files anew).
"""

from __future__ import annotations

import math
from pathlib import Path

from eoam_sumo.sim.scenario import ScenarioFiles

#: Options naming files SUMO writes during the run (besides those ending in "output"/"dump").
_WRITING_OPTIONS = (
    "summary",
    "tripinfo",
    "vehroute",
    "log",
    "message-log",
    "error-log",
    "save-state.times",
    "save-state.period",
    "save-state.files",
    "output-prefix",
)
#: Options of the coarse run: the state written at full precision, with what a restart needs.
SAVE_STATE_OPTIONS = (
    "--save-state.precision",
    "17",
    "--save-state.rng",
    "true",
    "--save-state.transportables",
    "true",
)
STATE_FILE = "handover.state.xml"


def _number(text) -> float | None:
    try:
        value = float(text)
    except (TypeError, ValueError):
        return None
    return value if math.isfinite(value) else None


def _writes_files(options: dict) -> bool:
    return any(
        key.endswith(("output", "dump")) or key in _WRITING_OPTIONS
        for key, value in options.items()
        if value
    )


def handover_plan(
    files: ScenarioFiles,
    ego_id: str,
    step_s: float,
    scripted: dict,
    extra: tuple[str, ...],
) -> tuple[float, float] | None:
    """(the sumocfg's step [s], handover time [s]) when the time before the ego's departure
    is to be run at the sumocfg's step, else None."""
    options = files.options
    coarse = _number(options.get("step-length"))
    given = {a.split("=", 1)[0].lstrip("-") for a in extra if a.startswith("-")}
    if (
        coarse is None
        or coarse <= step_s + 1e-9
        or "step-length" in given
        or "load-state" in given
        or "load-state" in options
        or _writes_files(options)
    ):
        return None
    begin = _number(options.get("begin", "0"))
    departs = [_number(files.vehicles[vid].attrs.get("depart", "0")) for vid in (ego_id, *scripted)]
    if begin is None or any(d is None for d in departs):
        return None
    until = min(d for d in departs if d is not None)
    # SUMO counts time in whole milliseconds: so does the handover
    coarse_ms, span_ms = round(coarse * 1000.0), round((until - begin) * 1000.0)
    n_steps = span_ms // coarse_ms
    if n_steps < 1:
        return None
    return coarse, begin + n_steps * coarse_ms / 1000.0


def run_and_hand_over(api, fine_cmd: list[str], handover_s: float, workdir: Path) -> None:
    """Step the SUMO that ``api`` runs (at the sumocfg's step, started with
    :data:`SAVE_STATE_OPTIONS`) to ``handover_s``, save its state and restart SUMO with
    ``fine_cmd`` (binary first) from that state."""
    while api.simulation.getTime() < handover_s - 5e-4:
        api.simulationStep()
    state = workdir / STATE_FILE
    api.simulation.saveState(str(state))
    api.load([*fine_cmd[1:], "--load-state", str(state)])
