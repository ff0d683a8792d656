"""A re-run replaces a finished output folder only once its new results are complete.

:func:`output_folder` locks ``PATH`` (:mod:`.lock`) and gives the command the folder to write:

- ``PATH`` new, or empty but for its lock file: ``PATH`` itself; unless ``keep_partial``
  (``protocol``: no ``--resume`` to finish it), what the command wrote is removed when it
  raises: a new ``PATH`` (and the parents made for it) whole, an empty one back to empty;
- ``PATH`` holding this kind of output (one of ``OutputKind.markers``, finished or not): a
  staging folder beside it, ``PATH.partial-<pid>``. When the command ends normally, the
  staging folder's paths recorded in its ``results.csv`` and ``summary.json`` files are made
  ``PATH``'s and it takes ``PATH``'s place (the old folder renamed aside, then removed); when
  it raises (bad input, a failure, Ctrl-C), the staging folder is removed and ``PATH`` is left
  as it was. A staging folder whose process died is removed by the next run into ``PATH``;
- ``in_place`` (``batch --resume``): ``PATH`` itself, whatever it holds of this kind;
- ``PATH`` holding anything else: refused (``InputError``), for a re-run would remove it.
"""

from __future__ import annotations

import contextlib
import glob
import os
import shutil
import signal
import threading
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from eoam_sumo.errors import InputError
from eoam_sumo.fileio import write_atomic
from eoam_sumo.outputs.lock import LOCK_NAME, locked, try_lock

#: The text files whose recorded paths move with the folder.
RECORDS = ("results.csv", "summary.json")


@dataclass(frozen=True)
class OutputKind:
    """A command's output folder: its name (in messages) and the entries that show a folder
    holds its output."""

    name: str
    markers: tuple[str, ...]
    #: entries that show a folder holds another command's output (results.csv and scenarios/
    #: are written by several commands): such a folder is refused, not replaced
    foreign: tuple[str, ...] = ()


@contextlib.contextmanager
def output_folder(
    path: Path, kind: OutputKind, *, in_place: bool = False, keep_partial: bool = True
) -> Iterator[Path]:
    """Lock ``path`` and yield the folder to write (module docstring); InputError in one line
    when another process writes it, it cannot be written, or it holds other files."""
    path = Path(path)
    made = _first_missing(path)
    with locked(path):
        names = _entries(path)
        other = sorted(names & set(kind.foreign))
        if other:
            raise InputError(
                f"output folder {path} holds another command's output ({', '.join(other)}), "
                f"not {kind.name} output; give a new or empty folder"
            )
        if names and not names & set(kind.markers):
            raise InputError(
                f"output folder {path} is not empty and holds no {kind.name} output (none of "
                f"{', '.join(kind.markers)}); give a new or empty folder"
            )
        if not names and not keep_partial:
            with _undone_on_error(path, made):
                yield path
            return
        if not names or in_place:
            if in_place and path.name not in ("", ".", ".."):
                _remove_stale(path)  # a killed run's staging folder, as a plain re-run does
            yield path
            return
        plain = path.name not in ("", ".", "..") and not path.is_symlink()
        with _staged(path if plain else path.resolve()) as stage:
            yield stage


def _first_missing(path: Path) -> Path | None:
    """The outermost of ``path`` and its parents that does not exist yet (None: it exists)."""
    missing = None
    for folder in (path, *path.parents):
        if folder.exists() or folder.is_symlink():
            break
        missing = folder
    return missing


@contextlib.contextmanager
def _undone_on_error(path: Path, made: Path | None) -> Iterator[None]:
    """When the block raises, what it wrote into the new or empty ``path`` is removed: the
    folders made for it (``made``) whole, else every entry but the lock file."""
    try:
        yield
    except BaseException:
        if made is not None:
            shutil.rmtree(made, ignore_errors=True)
        else:
            for entry in _entries(path):
                target = path / entry
                if target.is_dir() and not target.is_symlink():
                    shutil.rmtree(target, ignore_errors=True)
                else:
                    with contextlib.suppress(OSError):
                        target.unlink()
        raise


def _entries(path: Path) -> set[str]:
    try:
        return {p.name for p in path.iterdir()} - {LOCK_NAME}
    except OSError as exc:
        raise InputError(f"output folder {path} cannot be read: {exc.strerror}") from None


@contextlib.contextmanager
def _staged(path: Path) -> Iterator[Path]:
    """A locked staging folder beside ``path``, swapped into its place when the block ends
    normally, removed when it raises."""
    _remove_stale(path)
    stage = path.with_name(f"{path.name}.partial-{os.getpid()}")
    shutil.rmtree(stage, ignore_errors=True)
    with locked(stage):
        try:
            yield stage
            relocate(stage, path)
        except BaseException:
            shutil.rmtree(stage, ignore_errors=True)
            raise
        with _signals_deferred():
            _swap(stage, path)


def _remove_stale(path: Path) -> None:
    """Remove the staging (and set-aside) folders of ``path`` whose process is gone."""
    name = glob.escape(path.name)
    for pattern in (f"{name}.partial-*", f"{name}.old-*"):
        for sibling in path.parent.glob(pattern):
            with contextlib.suppress(InputError, OSError):
                fd = try_lock(sibling)
                if fd is not None:
                    shutil.rmtree(sibling, ignore_errors=True)
                    os.close(fd)


def relocate(stage: Path, final: Path) -> None:
    """Rewrite ``stage``'s paths recorded in its ``RECORDS`` files as ``final``'s."""
    pairs = [(str(stage.resolve()), str(final.resolve())), (str(stage), str(final))]
    for name in RECORDS:
        for file in sorted(stage.rglob(name)):
            text = file.read_text(encoding="utf-8")
            moved = text
            for old, new in pairs:
                moved = moved.replace(old, new)
            if moved != text:
                write_atomic(file, moved, durable=True)


def _swap(stage: Path, path: Path) -> None:
    """``stage`` into ``path``'s place: the old folder renamed aside, then removed."""
    old = path.with_name(f"{path.name}.old-{os.getpid()}")
    try:
        os.rename(path, old)
        try:
            os.rename(stage, path)
        except OSError:
            with contextlib.suppress(OSError):
                os.rename(old, path)
            raise
    except OSError as exc:
        raise RuntimeError(
            f"output folder {path} could not be replaced ({exc.strerror}); the new results "
            f"are in {stage}"
        ) from None
    shutil.rmtree(old, ignore_errors=True)


@contextlib.contextmanager
def _signals_deferred() -> Iterator[None]:
    """Ctrl-C and SIGTERM held back during the block (main thread only), then delivered."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught: list[int] = []
    held = (signal.SIGINT, signal.SIGTERM)
    previous = {s: signal.signal(s, lambda signum, _frame: caught.append(signum)) for s in held}
    try:
        yield
    finally:
        for s, handler in previous.items():
            signal.signal(s, signal.SIG_DFL if handler is None else handler)
        for signum in caught:
            signal.raise_signal(signum)
