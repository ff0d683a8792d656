"""Saving a figure: matplotlib's Agg canvas through the object interface (no pyplot); and
drawing several figures at once."""

from __future__ import annotations

import os
import select
import signal
import sys
from collections.abc import Callable, Sequence
from pathlib import Path

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure


def save(fig: Figure, path: Path, dpi: int = 120) -> Path:
    """Render ``fig`` to a PNG at ``path`` (parents created)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    FigureCanvasAgg(fig)
    fig.savefig(path, dpi=dpi)
    return path


#: The longest a forked copy may take to draw its figure before it is killed and the figure
#: drawn in this process instead [s].
FORK_TIMEOUT_S = 300.0


def draw_all(draws: Sequence[Callable[[], Path]]) -> list[Path]:
    """Call each of ``draws`` (each draws and saves one figure, returns its path), the first
    in this process and the others each in a forked copy of it at the same time (matplotlib
    imported once, here, and each figure the same code on the same data, so the same
    pictures). A copy that fails, or no ``os.fork``: that figure is drawn here afterwards,
    raising as it would have."""
    if len(draws) < 2 or not hasattr(os, "fork"):
        return [draw() for draw in draws]
    sys.stdout.flush()
    sys.stderr.flush()
    children = [_forked(draw) for draw in draws[1:]]
    paths = [draws[0]()]
    for draw, child in zip(draws[1:], children):
        path = _joined(*child) if child else None
        paths.append(draw() if path is None else path)
    return paths


def _forked(draw: Callable[[], Path]) -> tuple[int, int] | None:
    """(process id, pipe to read) of a forked copy that calls ``draw``, writes the path it
    returns into the pipe and exits 0 (1 if it raised); None when it cannot fork."""
    read_fd, write_fd = os.pipe()
    try:
        pid = os.fork()
    except OSError:
        os.close(read_fd)
        os.close(write_fd)
        return None
    if pid == 0:  # the copy: never returns
        code = 1
        try:
            os.close(read_fd)
            os.write(write_fd, os.fsencode(draw()))
            code = 0
        finally:
            os._exit(code)
    os.close(write_fd)
    return pid, read_fd


def _joined(pid: int, read_fd: int) -> Path | None:
    """The path a forked copy drew, once it has exited; None if it failed, or gave no path
    within ``FORK_TIMEOUT_S`` (killed: a copy forked while another thread held a lock may
    never get it)."""
    ready, _, _ = select.select([read_fd], [], [], FORK_TIMEOUT_S)
    if not ready:
        os.kill(pid, signal.SIGKILL)
    with os.fdopen(read_fd, "rb") as fh:
        data = fh.read() if ready else b""
    _, status = os.waitpid(pid, 0)
    return Path(os.fsdecode(data)) if status == 0 and data else None
