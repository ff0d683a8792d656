"""Atomic file writes: a reader sees the old file or the new one, never a part of either."""

from __future__ import annotations

import contextlib
import os
from pathlib import Path

from eoam_sumo.errors import InputError


def write_atomic(path: Path, data: str | bytes, *, durable: bool = False) -> Path:
    """Write ``data`` (text as UTF-8, newlines kept as given) to ``path`` through a temporary
    file beside it and ``os.replace``; ``durable`` also syncs the file to disk first (for
    results that must survive a power cut, as results.csv). On failure the temporary file is
    removed, ``path`` left as it was, and ``InputError`` names ``path`` (a folder of that name,
    a read-only or full disk)."""
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    raw = data.encode("utf-8") if isinstance(data, str) else data
    try:
        with open(tmp, "wb") as fh:
            fh.write(raw)
            if durable:
                fh.flush()
                os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            tmp.unlink()
        if isinstance(exc, OSError):
            raise InputError(f"{path} cannot be written: {exc.strerror or exc}") from None
        raise
    return path


def writable_dir(path: Path) -> Path:
    """``path`` created if needed; ``InputError`` naming it when it cannot be written."""
    try:
        path.mkdir(parents=True, exist_ok=True)
        probe = path / ".eoam-write-test"
        probe.write_text("")
        probe.unlink()
    except OSError as exc:
        raise InputError(f"output folder {path} cannot be written: {exc.strerror}") from None
    return path
