"""What a case's results depend on beside its parameters: the bytes of the files it reads.

``inputs_sha256`` (a results.csv column) is the SHA-256 of a case's scenario files, in a
fixed order: its ``.sumocfg`` and the net, route and additional files it names, and the ego's
vehicle file when the case names one (a catalogue name or the user's own ``.toml``). A
generated scenario (``road``/``los`` cases) is made from the case's parameters and seed,
so only its vehicle file counts. ``batch --resume`` runs a case again when its digest
changed: a scenario file edited since the row was written no longer passes for the same case.

The digest is of the files' bytes, not of their paths (the sumocfg's path is a case
parameter of its own). A file that cannot be read counts as missing (the case then fails on
its own, naming it).
"""

from __future__ import annotations

import hashlib
import xml.etree.ElementTree as ET
from pathlib import Path

from eoam_sumo.errors import InputError
from eoam_sumo.matrix import Case
from eoam_sumo.vehicle_files import is_vehicle_file, vehicle_path

#: the results.csv column
INPUTS_COLUMN = "inputs_sha256"
#: the sumocfg options whose files SUMO reads for the scenario
SCENARIO_OPTIONS = ("net-file", "route-files", "additional-files")
_MISSING = b"\0missing\0"


class InputDigests:
    """Each case's ``inputs_sha256``, every file read at most once (a matrix's cases share
    their scenario)."""

    def __init__(self) -> None:
        self._bytes: dict[Path, bytes] = {}
        self._named: dict[Path, tuple[Path, ...]] = {}
        self._digests: dict[tuple, str] = {}

    def of(self, case: Case) -> str:
        key = (case.traffic() is None, str(case.sumocfg), case.vehicle)
        digest = self._digests.get(key)
        if digest is None:
            digest = self._digests[key] = self._digest(case)
        return digest

    def _digest(self, case: Case) -> str:
        digest = hashlib.sha256()
        for role, path in self._files(case):
            data = self._read(path)
            digest.update(f"{role}:{len(data)}:".encode())
            digest.update(data)
        return digest.hexdigest()

    def _files(self, case: Case) -> list[tuple[str, Path]]:
        files = []
        if case.traffic() is None:
            cfg = Path(case.sumocfg)
            files.append(("sumocfg", cfg))
            files += [("scenario", p) for p in self._scenario_files(cfg)]
        if case.vehicle is not None:
            files.append(("vehicle", _vehicle_file(case.vehicle)))
        return files

    def _scenario_files(self, cfg: Path) -> tuple[Path, ...]:
        """The files the sumocfg names for its options ``SCENARIO_OPTIONS``, in order."""
        named = self._named.get(cfg)
        if named is None:
            named = self._named[cfg] = _named_files(cfg, self._read(cfg))
        return named

    def _read(self, path: Path) -> bytes:
        data = self._bytes.get(path)
        if data is None:
            try:
                data = path.read_bytes()
            except OSError:
                data = _MISSING
            self._bytes[path] = data
        return data


def _named_files(cfg: Path, text: bytes) -> tuple[Path, ...]:
    """The net, route and additional files of a sumocfg's text (relative to its folder);
    none when it is not readable XML."""
    try:
        root = ET.fromstring(text)
    except ET.ParseError:
        return ()
    files = []
    for option in SCENARIO_OPTIONS:
        for elem in root.iter(option):
            names = elem.get("value", "").split(",")
            files += [cfg.parent / name.strip() for name in names if name.strip()]
    return tuple(files)


def _vehicle_file(vehicle: str) -> Path:
    """The file of a catalogue name or a vehicle file (a path that does not resolve: as
    given, read as missing)."""
    try:
        return vehicle_path(vehicle)
    except InputError:  # an unknown vehicle fails its case, naming it
        return Path(vehicle) if is_vehicle_file(vehicle) else Path(f"{vehicle}.toml")
