"""One writer per output folder: an exclusive ``flock`` on ``FOLDER/.eoam-sumo.lock``.

The kernel releases a ``flock`` when its process ends, however it ends, so a lock is never
stale. The lock file holds the holder's process id while it is held (named in the refusal) and
is left in place, empty, afterwards: removing a lock file that another process may have opened
would let two processes each lock a different file of the same name.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
from collections.abc import Iterator
from pathlib import Path

from eoam_sumo.errors import InputError

LOCK_NAME = ".eoam-sumo.lock"


def _open_lock_file(folder: Path) -> int:
    """The folder's lock file opened for writing (the folder made if needed); InputError
    naming the folder when it cannot be made or written."""
    if folder.exists() and not folder.is_dir():
        raise InputError(f"output folder {folder} cannot be written: it is not a folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
        return os.open(folder / LOCK_NAME, os.O_RDWR | os.O_CREAT, 0o644)
    except OSError as exc:
        raise InputError(
            f"output folder {folder} cannot be written: {exc.strerror or exc}"
        ) from None


def try_lock(folder: Path) -> int | None:
    """The descriptor of the folder's lock file, locked; None when another process holds it."""
    fd = _open_lock_file(folder)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        os.close(fd)
        return None
    return fd


def holder_pid(folder: Path) -> int | None:
    """The process id the folder's lock file names (None when it names none)."""
    try:
        text = (folder / LOCK_NAME).read_text(encoding="ascii").strip()
    except (OSError, UnicodeDecodeError):
        return None
    return int(text) if text.isdigit() else None


@contextlib.contextmanager
def locked(folder: Path) -> Iterator[None]:
    """Hold ``folder``'s lock for the block (the folder made if needed). InputError in one
    line, naming the folder and the holder's process id, when another process writes it."""
    folder = Path(folder)
    fd = try_lock(folder)
    if fd is None:
        pid = holder_pid(folder)
        holder = f" (process {pid})" if pid else ""
        raise InputError(
            f"output folder {folder} is being written by another eoam-sumo process{holder}; "
            "wait for it to end or give another --out"
        )
    try:
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode("ascii"), 0)
        yield
    finally:
        with contextlib.suppress(OSError):
            os.ftruncate(fd, 0)
        os.close(fd)
