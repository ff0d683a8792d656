"""Vehicle files: a ``VehicleParams`` as TOML, every value with its unit and its source.

A vehicle file has one table per parameter of ``params.VehicleParams``::

    [mass_kg]
    value = 1723.0
    unit = "kg"
    source = "CarSim E-class sedan table, Jing et al., IEEE T-ITS 2022"

Every parameter must be present, with the unit the dataclass states and a non-empty source;
unknown keys are refused (a misspelt key would otherwise fall back to the sedan's value).
``--vehicle NAME`` looks NAME up in the catalogue (``vehicles/NAME.toml``); anything with a
``.toml`` suffix or a path separator is read as the user's own file.
"""

from __future__ import annotations

import dataclasses
import math
import os
import tomllib
from collections.abc import Mapping
from pathlib import Path

from eoam_sumo.errors import InputError
from eoam_sumo.params import G_MPS2, VehicleParams, VehicleValueError
from eoam_sumo.textfiles import not_utf8

DEFAULT_VEHICLE = "sedan"


def default_vehicles_dir() -> Path:
    """``$EOAM_VEHICLES_DIR`` if set, else the repository's ``vehicles/``."""
    env = os.environ.get("EOAM_VEHICLES_DIR")
    if env:
        return Path(env)
    return Path(__file__).resolve().parents[1] / "vehicles"


def catalogue(directory: Path | None = None) -> list[str]:
    """Names of the catalogue's vehicles (file stems), sorted."""
    folder = directory or default_vehicles_dir()
    return sorted(p.stem for p in folder.glob("*.toml"))


def is_vehicle_file(name_or_file: str) -> bool:
    """Whether ``--vehicle`` names a file (a ``.toml`` suffix or a path separator), not a
    catalogue vehicle."""
    text = str(name_or_file)
    return text.endswith(".toml") or os.sep in text or "/" in text


def shadows_catalogue(name_or_file: str, directory: Path | None = None) -> bool:
    """Whether ``--vehicle`` is a user's file named as a catalogue vehicle (``./sedan.toml``),
    other than the catalogue's own file."""
    if not is_vehicle_file(name_or_file):
        return False
    path = Path(name_or_file)
    stem = path.stem if path.suffix == ".toml" else path.name
    own = (directory or default_vehicles_dir()) / f"{stem}.toml"
    return own.is_file() and own.resolve() != path.resolve()


def vehicle_path(name_or_file: str, directory: Path | None = None) -> Path:
    """The file of a catalogue NAME, or the user's own FILE; ``InputError`` if neither."""
    text = str(name_or_file)
    if is_vehicle_file(text):
        path = Path(text)
        if not path.is_file():
            raise InputError(f"{path}: no such vehicle file")
        return path
    folder = directory or default_vehicles_dir()
    path = folder / f"{text}.toml"
    if not path.is_file():
        known = ", ".join(catalogue(folder)) or "none"
        raise InputError(f"--vehicle {text!r}: not in the catalogue ({known}) nor a .toml file")
    return path


#: The parameters of each vehicle file this process checked, by its path and bytes: a batch's
#: cases share one vehicle without parsing it again; an edited file is checked again.
_LOADED: dict[tuple[str, bytes], VehicleParams] = {}
_LOADED_MAX = 64  # files kept; the oldest goes first


def load_vehicle(name_or_file: str, directory: Path | None = None) -> VehicleParams:
    """The ``VehicleParams`` of a catalogue NAME or a vehicle FILE (checked, see module doc)."""
    path = vehicle_path(name_or_file, directory)
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise InputError(f"{path}: cannot read: {exc}") from None
    key = (str(path), raw)
    params = _LOADED.get(key)
    if params is None:
        params = _parsed(path, raw)
        if len(_LOADED) >= _LOADED_MAX:
            _LOADED.pop(next(iter(_LOADED)))
        _LOADED[key] = params
    return params


def _parsed(path: Path, raw: bytes) -> VehicleParams:
    """A vehicle file's bytes parsed and checked."""
    try:
        data = tomllib.loads(raw.decode("utf-8"))
    except UnicodeDecodeError as exc:
        raise not_utf8(path, exc, "vehicle file") from None
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{path}: not valid TOML: {exc}") from None
    return params_from_tables(data, path)


def params_from_tables(data: dict, path: Path) -> VehicleParams:
    """``VehicleParams`` from a vehicle file's parsed tables; ``InputError`` names the key."""
    fields = {f.name: f for f in dataclasses.fields(VehicleParams)}
    unknown = sorted(set(data) - set(fields))
    if unknown:
        raise InputError(f"{path}: unknown key {unknown[0]!r} (a VehicleParams field expected)")
    values = {name: _value(data, f, path) for name, f in fields.items()}
    try:
        return VehicleParams(**values)
    except VehicleValueError as exc:
        raise InputError(f"{path}: key {exc.field!r} {exc.detail}") from None


def _value(data: dict, f: dataclasses.Field, path: Path):
    """One parameter's value, its type, unit and source checked."""
    entry = data.get(f.name)
    if entry is None:
        raise InputError(f"{path}: key {f.name!r} is missing")
    if not isinstance(entry, dict) or "value" not in entry:
        raise InputError(f"{path}: key {f.name!r} must be a table with value, unit and source")
    unit = f.metadata.get("unit", "")
    if entry.get("unit") != unit:
        raise InputError(f"{path}: key {f.name!r} has unit {entry.get('unit')!r}, not {unit!r}")
    source = entry.get("source")
    if not isinstance(source, str) or not source.strip():
        raise InputError(f"{path}: key {f.name!r} has no source")
    return _typed(entry["value"], f, path)


def _typed(value, f: dataclasses.Field, path: Path):
    """The value in the field's type (the default's); its range is the dataclass's check."""
    kind = type(f.default)
    if kind is float and isinstance(value, (int, float)) and not isinstance(value, bool):
        try:
            return float(value)
        except OverflowError:
            raise InputError(f"{path}: key {f.name!r} = {value} is too large for a float") from None
    if isinstance(value, kind) and not (kind is int and isinstance(value, bool)):
        return value
    raise InputError(f"{path}: key {f.name!r} = {value!r} must be a {kind.__name__}")


def vehicle_toml(
    params: VehicleParams, sources: Mapping[str, str] | None = None, header: str = ""
) -> str:
    """The vehicle file of ``params``: every field with its unit and its source, the source
    from ``sources`` where given (a catalogue vehicle's own), else the dataclass's; ``header``
    as comment lines on top."""
    given = sources or {}
    unknown = sorted(set(given) - {f.name for f in dataclasses.fields(params)})
    if unknown:
        raise ValueError(f"sources for unknown keys: {unknown}")
    blocks = [_comment(header)] if header else []
    for f in dataclasses.fields(params):
        lines = [
            f"[{f.name}]",
            f"value = {_toml_scalar(getattr(params, f.name))}",
            f"unit = {_toml_scalar(f.metadata.get('unit', ''))}",
            f"source = {_toml_scalar(given.get(f.name, f.metadata.get('source', '')))}",
        ]
        blocks.append("\n".join(lines))
    return "\n\n".join(blocks) + "\n"


def _comment(text: str) -> str:
    return "\n".join(f"# {line}".rstrip() for line in text.strip().splitlines())


def sources_of(name_or_file: str, directory: Path | None = None) -> dict[str, str]:
    """Each parameter's source as a vehicle file states it."""
    path = vehicle_path(name_or_file, directory)
    with path.open("rb") as fh:
        data = tomllib.load(fh)
    return {key: str(entry.get("source", "")) for key, entry in data.items()}


def static_stability_factor(params: VehicleParams) -> float:
    """NHTSA's static stability factor ``t / (2 h)``: the lateral acceleration [g] at which a
    rigid vehicle would tip (no suspension roll)."""
    return params.track_m / (2.0 * params.cg_height_m)


def dynamic_index(params: VehicleParams) -> float:
    """The dynamic index ``k^2 / (a b)`` with ``k^2 = Iz / m`` (1 when the yaw inertia is
    that of two masses at the axles; passenger cars are close to 1, SAE 1999-01-1336)."""
    k2 = params.yaw_inertia_kgm2 / params.mass_kg
    return k2 / (params.cg_to_front_m * params.cg_to_rear_m)


def _toml_scalar(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, int):
        return str(value)
    escaped = str(value).replace("\\", "\\\\").replace('"', '\\"')
    return f'"{escaped}"'


#: The catalogue table's columns (docs/vehicles.md "The vehicles").
CATALOGUE_HEADER = (
    "| name | vehicle | drive | ABS / ESC | mass kg | Iz kg m^2 | a / b m | h m | track m | SSF "
    "| k^2/(a b) | L x W m | brake front share | C_f / C_r kN/rad | linear understeer deg/g |"
)


def catalogue_row(name: str, directory: Path | None = None) -> str:
    """One vehicle's row of the catalogue table (``CATALOGUE_HEADER``), from its file."""
    p = load_vehicle(name, directory)
    fitted = f"{'yes' if p.abs_fitted else 'no'} / {'yes' if p.esc_fitted else 'no'}"
    cells = (
        f"`{name}`",
        p.name,
        p.drivetrain.upper().replace("EAWD", "eAWD"),
        fitted,
        f"{p.mass_kg:.0f}",
        f"{p.yaw_inertia_kgm2:.0f}",
        f"{p.cg_to_front_m:.3f} / {p.cg_to_rear_m:.3f}",
        f"{p.cg_height_m:.3f}",
        f"{p.track_m:.3f}",
        f"{static_stability_factor(p):.2f}",
        f"{dynamic_index(p):.2f}",
        f"{p.length_m:.2f} x {p.width_m:.2f}",
        f"{p.brake_front_share:.3f}",
        f"{p.front_axle_stiffness_npr / 1e3:.0f} / {p.cornering_stiffness_rear_npr / 1e3:.0f}",
        f"{math.degrees(p.understeer_gradient_rad_per_mps2 * G_MPS2):.2f}",
    )
    return "| " + " | ".join(cells) + " |"
