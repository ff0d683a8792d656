"""Which code runs: the compiled modules (setup.py compiles them with mypyc) or the sources.

A build records the SHA-256 of every source it compiled in ``compiled_sources.json`` beside
the extension modules (or why compiling failed). When the package is imported, :func:`choose`
compares them with the sources: if one differs (a source edited since the build) or an
extension module has no record, every module of the package is imported from its source, with
a RuntimeWarning that says to rebuild (``make``, or ``pip install -e .``): compiled modules call
each other directly, so a mix would still run the old code. An install whose compiling failed
warns too. ``EOAM_SUMO_PURE=1`` imports the sources without a warning. Results are the same
either way; only the speed differs.
"""

from __future__ import annotations

import hashlib
import json
import os
import sys
import warnings
from importlib import machinery
from pathlib import Path

PACKAGE_DIR = Path(__file__).resolve().parent
MANIFEST = PACKAGE_DIR / "compiled_sources.json"  # {"compiled": {source: SHA-256}, "failed"}
PURE_ENV = "EOAM_SUMO_PURE"


def source_digest(path: Path) -> str:
    """SHA-256 of a source file, as a build records it."""
    return hashlib.sha256(path.read_bytes()).hexdigest()


def extension_modules(package_dir: Path = PACKAGE_DIR) -> list[Path]:
    """The extension modules of a source tree's package whose source lies beside them."""
    return sorted(
        ext
        for suffix in machinery.EXTENSION_SUFFIXES
        for ext in package_dir.rglob(f"*{suffix}")
        if ext.with_name(ext.name[: -len(suffix)] + ".py").is_file()
    )


def build_record(package_dir: Path = PACKAGE_DIR) -> dict:
    """What the build wrote: ``compiled`` (source path from the root -> SHA-256) and ``failed``
    (why compiling failed, or None); empty without a record."""
    manifest = package_dir / MANIFEST.name
    return json.loads(manifest.read_text()) if manifest.is_file() else {}


def stale_sources(package_dir: Path = PACKAGE_DIR) -> list[str]:
    """Sources (paths from the root) whose extension module was not built from them as they
    are now: changed since the build, or with no record of it."""
    root = package_dir.parent
    built = build_record(package_dir).get("compiled", {})
    stale = [
        rel
        for rel, sha in built.items()
        if not (root / rel).is_file() or source_digest(root / rel) != sha
    ]
    for ext in extension_modules(package_dir):
        rel = ext.relative_to(root).as_posix().split(".", 1)[0] + ".py"
        if rel not in built:
            stale.append(rel)
    return sorted(set(stale))


def compiled() -> bool:
    """Whether the step loop runs compiled (its module was imported from an extension)."""
    from eoam_sumo.sim import cosim

    return isinstance(getattr(cosim.__spec__, "loader", None), machinery.ExtensionFileLoader)


class SourcesOnly:
    """Meta path finder: the package's modules from their sources, never an extension."""

    @staticmethod
    def find_spec(name, path=None, target=None):
        if path is None or not name.startswith(f"{__package__}."):
            return None
        for entry in path:
            finder = machinery.FileFinder(
                entry, (machinery.SourceFileLoader, machinery.SOURCE_SUFFIXES)
            )
            spec = finder.find_spec(name, target)
            if spec is not None:
                return spec
        return None


def choose() -> None:
    """Import the sources instead of the compiled modules when asked or when stale."""
    if any(isinstance(f, SourcesOnly) for f in sys.meta_path):
        return
    if os.environ.get(PURE_ENV):
        sys.meta_path.insert(0, SourcesOnly())
        return
    failed = build_record().get("failed")
    if failed:
        warnings.warn(
            f"eoam_sumo runs its Python sources: the install built no compiled "
            f"modules ({failed}); the step loop is slower",
            RuntimeWarning,
            stacklevel=3,
        )
    stale = stale_sources()
    if stale:
        named = ", ".join(stale[:3]) + (f" and {len(stale) - 3} more" if len(stale) > 3 else "")
        warnings.warn(
            f"eoam_sumo runs its Python sources: the compiled modules were not built from "
            f"{named} as they are now; rebuild with 'make' or 'pip install -e .' (or set "
            f"{PURE_ENV}=1)",
            RuntimeWarning,
            stacklevel=3,
        )
        sys.meta_path.insert(0, SourcesOnly())
