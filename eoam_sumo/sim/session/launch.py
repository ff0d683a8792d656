"""Starting and ending SUMO: the command line with the options the co-simulation needs,
libsumo in-process or a TraCI server process, and SUMO's own error messages on failure."""

from __future__ import annotations

import contextlib
import io
import os
import subprocess
import sys
from pathlib import Path

#: Options the co-simulation sets over the scenario's sumocfg (option, value), and why:
#: SUMO must never remove, teleport or stop a vehicle for a collision (the contact test of the
#: co-simulation is the ground truth; the ego moved by moveToXY overlaps others by design),
#: and must load every route at the start (by default SUMO may read a vehicle listed after
#: another with the same departure only in its departure step, too late to re-insert it as
#: the ego). SUMO's ballistic update at every step (constant acceleration over a step, as the
#: multi-rate co-simulation interpolates; SUMO's default Euler update moves a braking vehicle
#: by its new speed, stopping it ``v dt / 2`` short: SUMO user documentation, Simulation/Basic
#: Definition, "Defining the Integration Method"), so every SUMO step runs one physics.
#: ``no-warnings`` and ``no-step-log`` keep the terminal quiet; a sumocfg that turns warnings
#: on (``no-warnings`` false) keeps them.
ENFORCED_OPTIONS = (
    ("step-method.ballistic", "true"),
    ("collision.action", "none"),
    ("time-to-teleport", "-1"),
    ("no-warnings", "true"),
    ("no-step-log", "true"),
    ("route-steps", "0"),
)
HONOURED_OPTIONS = ("no-warnings", "window-size")  # left as the sumocfg sets them, if it does
GUI_WINDOW_SIZE = "1280,800"  # sumo-gui's window [px] (its default is a small one)
ERROR_LOG_STDERR = "sumo-stderr.log"  # SUMO's standard error while libsumo starts (workdir)
TRACI_RETRIES = 600  # x 50 ms: time SUMO may take to load before TraCI gives up
PROCESS_EXIT_S = 10.0  # time a closed SUMO server process gets to exit
_TRUE, _FALSE = ("true", "1", "yes", "on", "x"), ("false", "0", "no", "off", "-")


def _same_value(a: str | None, b: str) -> bool:
    """Two option values mean the same (numbers by value, booleans by SUMO's words)."""
    if a is None:
        return False
    a, b = a.strip().lower(), b.strip().lower()
    if a == b or (a in _TRUE and b in _TRUE) or (a in _FALSE and b in _FALSE):
        return True
    try:
        return float(a) == float(b)
    except ValueError:
        return False


def sumo_command(
    binary: str,
    cfg: Path,
    cfg_options: dict,
    step_s: float,
    error_log: Path,
    extra: tuple[str, ...],
    gui: bool,
    keep_gui_open: bool = False,
) -> tuple[list[str], dict]:
    """(command line, overrides): SUMO started on ``cfg`` with the co-simulation's options,
    and option -> value of every one of them that changes what the sumocfg (``cfg_options``,
    its option elements) or SUMO's default gives. Options in ``extra`` win over both. sumo-gui
    starts at once, and quits at the end unless ``keep_gui_open``."""
    wanted = [("step-length", f"{step_s:.3f}")]
    for option, value in ENFORCED_OPTIONS:
        if option in HONOURED_OPTIONS and option in cfg_options:
            continue
        wanted.append((option, value))
    if gui:
        wanted.append(("start", "true"))
        if "window-size" not in cfg_options:
            wanted.append(("window-size", GUI_WINDOW_SIZE))
        if not keep_gui_open:
            wanted.append(("quit-on-end", "true"))
    given = {a.split("=", 1)[0].lstrip("-") for a in extra if a.startswith("-")}
    cmd = [binary, "-c", str(cfg)]
    if "error-log" not in cfg_options:
        cmd += ["--error-log", str(error_log)]
    overrides = {}
    for option, value in wanted:
        if option in given:
            continue
        cmd += [f"--{option}", value]
        if not _same_value(cfg_options.get(option), value):
            overrides[option] = value
    return [*cmd, *extra], overrides


def shut_down(api, process, *, wait: bool = True) -> None:
    """Close the connection to SUMO (errors of an already dead SUMO ignored), end its process
    (``wait`` False: leave a sumo-gui window open for the user to close)."""
    with contextlib.suppress(Exception):
        api.close()
    if wait:
        end_process(process)


def end_process(process) -> None:
    """Wait for a SUMO server process to end (it was told to close or failed), else kill it."""
    if process is None:
        return
    try:
        process.wait(timeout=PROCESS_EXIT_S)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()


def traci_connect(cmd: list[str]):
    """Start SUMO as a TraCI server and connect, polling every 50 ms (traci.start waits 1 s
    and prints while it retries)."""
    import sumolib
    import traci

    port = sumolib.miscutils.getFreeSocketPort()
    proc = subprocess.Popen([*cmd, "--remote-port", str(port)], stdout=subprocess.DEVNULL)
    try:
        with contextlib.redirect_stdout(io.StringIO()):
            conn = traci.connect(port, numRetries=TRACI_RETRIES, waitBetweenRetries=0.05)
    except BaseException:
        end_process(proc)
        raise
    return conn, proc


@contextlib.contextmanager
def stderr_into(path: Path):
    """Send this process's standard error (file descriptor 2) to ``path`` meanwhile: in-process
    SUMO reports errors met while loading the routes at start there, not to its error log."""
    sys.stderr.flush()
    saved = os.dup(2)
    try:
        with open(path, "ab") as sink:
            os.dup2(sink.fileno(), 2)
        yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)


def start_error(cfg: Path, error_log: Path, exc: BaseException) -> str:
    """One line with SUMO's own error messages: the errors in its error log and in what it
    wrote to standard error while starting (never its warnings: a warning logged before the
    error is not the reason), else the exception's text."""
    text = ""
    for log in (error_log, error_log.with_name(ERROR_LOG_STDERR)):
        with contextlib.suppress(OSError):
            text += log.read_text(errors="replace")
    errors = sumo_errors(text) or sumo_errors(str(exc))
    detail = " ".join(dict.fromkeys(errors))  # each message once (both logs may hold it)
    return f"{cfg}: SUMO could not load the scenario: {detail or type(exc).__name__}"


def sumo_errors(text: str) -> list[str]:
    """SUMO's error messages in ``text`` (a log), without their "Error: " prefix: each message
    begins a line with "Error: " or "Warning: " and may run on over the lines that follow;
    lines before the first such line are errors too (an exception's text has no prefix).
    Warnings and SUMO's "Quitting (on error)." are left out."""
    messages: list[list[str]] = []
    kinds: list[str] = []
    for raw in text.splitlines():
        line = raw.strip()
        if not line or line == "Quitting (on error).":
            continue
        kind = next((k for k in ("Error: ", "Warning: ") if line.startswith(k)), "")
        if kind or not messages:
            messages.append([line.removeprefix(kind)])
            kinds.append(kind or "Error: ")
        else:
            messages[-1].append(line)
    return [" ".join(m) for m, kind in zip(messages, kinds, strict=True) if kind == "Error: "]
