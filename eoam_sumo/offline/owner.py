"""Whose tables a folder holds: ``eoam-sumo tables`` never writes over another vehicle's.

A tables folder's ``metadata.json`` names its vehicle (``vehicle_name``) and records its
parameters (``vehicle``, and since the vehicle catalogue their digest ``vehicle_digest``,
``tables.vehicle_digest``). A folder belongs to another vehicle when the name differs, the
digest differs, or (metadata without a digest) a recorded parameter value differs.
"""

from __future__ import annotations

import json
from pathlib import Path

from eoam_sumo.errors import InputError
from eoam_sumo.offline.tables import METADATA_NAME, vehicle_digest
from eoam_sumo.params import VehicleParams, describe


def _recorded(path: Path) -> tuple[str | None, str | None, dict]:
    """(vehicle name, digest, parameter values) of a tables folder's metadata file."""
    try:
        metadata = json.loads(path.read_text(encoding="utf-8"))
        stored = metadata.get("vehicle", {})
        values = {k: v["value"] for k, v in stored.items() if isinstance(v, dict) and "value" in v}
    except (OSError, UnicodeDecodeError, ValueError, AttributeError) as exc:
        raise InputError(
            f"{path}: cannot be read ({exc}), so whose tables the folder holds is unknown; "
            "give another --out, or --overwrite to replace them"
        ) from None
    return (
        metadata.get("vehicle_name") or values.get("name"),
        metadata.get("vehicle_digest"),
        values,
    )


def other_vehicle(folder: Path, params: VehicleParams) -> str | None:
    """What shows ``folder`` holds another vehicle's tables than ``params``'s (None when it
    holds none, or this vehicle's)."""
    path = Path(folder) / METADATA_NAME
    if not path.is_file():
        return None
    name, digest, values = _recorded(path)
    mine = vehicle_digest(params)
    wanted = {k: json.loads(json.dumps(v["value"])) for k, v in describe(params).items()}
    differing = [
        k
        for k, v in values.items()
        if k != "name" and not k.startswith("esc_") and k in wanted and wanted[k] != v
    ]
    if name == params.name and digest in (None, mine) and not differing:
        return None
    if digest:
        what = f"digest {digest}"
    else:
        what = f"other {', '.join(differing[:3])}" if differing else "another name"
    return f"the tables of {name!r} ({what}), not of {params.name!r} (digest {mine})"


def check_owner(folder: Path, params: VehicleParams) -> None:
    """InputError in one line when ``folder`` holds another vehicle's tables."""
    other = other_vehicle(folder, params)
    if other:
        raise InputError(
            f"{folder} holds {other}; give another --out, or --overwrite to replace them"
        )
