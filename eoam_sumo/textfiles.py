"""Reading the user's text files: every one is UTF-8; anything else is refused naming the file."""

from __future__ import annotations

from pathlib import Path

from eoam_sumo.errors import InputError


def not_utf8(path: Path | str, exc: UnicodeDecodeError, what: str) -> InputError:
    """The one-line error of ``what`` at ``path`` that is not UTF-8 text."""
    return InputError(
        f"{path}: cannot read the {what}: not UTF-8 text (byte {exc.object[exc.start]:#04x} "
        f"at offset {exc.start})"
    )


def read_utf8(path: Path | str, what: str) -> str:
    """The text of ``path``; ``InputError`` naming it and ``what`` it is when it cannot be
    read or is not UTF-8."""
    try:
        return Path(path).read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise not_utf8(path, exc, what) from None
    except OSError as exc:
        raise InputError(f"{path}: cannot read the {what}: {exc.strerror}") from None
