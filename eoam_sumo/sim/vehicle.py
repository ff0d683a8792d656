"""The ego's vehicle in a run: the folder of its lookup tables, and the limits past which it
rolls over.

Tables: the default vehicle (``vehicle_files.DEFAULT_VEHICLE``, the paper's sedan) uses the
tables folder itself (``$EOAM_TABLES_DIR`` or the repository's ``tables/``, or the folder a
run names); any other vehicle its sub-folder named after it: ``tables/<name>/``, ``<name>``
the catalogue name or the vehicle file's stem (``--vehicle trucks/truck.toml``:
``tables/truck/``; a user's file named as a catalogue vehicle, ``./pickup.toml``, has
``-file`` after its name, ``tables/pickup-file/``, so it never shares the catalogue vehicle's
tables); a run whose ABS is not the vehicle file's has ``-abs`` or ``-noabs`` after the name
(``tables/sedan-abs/``: the paper's sedan with ABS). ``eoam-sumo tables --vehicle NAME
[--abs on|off]`` builds them there; a run refuses a vehicle whose folder holds no tables or
tables built for other parameters (``offline.tables.LookupTables.load``).

Rollover (a loss of control, ``sim/outcome.py``): both inner wheels (front and rear of the side
the lateral transfer unloads) have lost their normal load under the plant's quasi-static load
transfer (``plant.model.tyre_loads_n``: static, plus ``m ax h / L`` along and
``m ay h / track`` across, shared between the axles by the roll stiffness), or the lateral
acceleration exceeds the static stability limit of the rigid vehicle, ``|ay| > g track / (2 h)``
(the static stability factor, Gillespie, *Fundamentals of Vehicle Dynamics*, 1992, ch. 9). One
inner wheel lifting is reported, not a loss of control; a rear wheel unloaded by braking alone
(pitch, no roll) is neither.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import NamedTuple

from eoam_sumo.errors import InputError
from eoam_sumo.offline.tables import METADATA_NAME, LookupTables, default_tables_dir
from eoam_sumo.params import G_MPS2, VehicleParams
from eoam_sumo.plant.model import AX_LOAD, AY_LOAD, STATE_NAMES, tyre_loads_n
from eoam_sumo.plant.ops import FLOAT_OPS
from eoam_sumo.vehicle_files import DEFAULT_VEHICLE, load_vehicle, shadows_catalogue

#: The tyres in the order of ``plant.model.tyre_loads_n``.
TYRES = ("front left", "front right", "rear left", "rear right")


def vehicle_name(vehicle: str) -> str:
    """The name a vehicle's tables folder and case ids use: the catalogue name, or a vehicle
    file's stem."""
    path = Path(vehicle)
    return path.stem if path.suffix == ".toml" else path.name


def tables_name(vehicle: str, params: VehicleParams | None = None) -> str:
    """The name of ``vehicle``'s tables folder: its name (``vehicle_name``; ``NAME-file`` for a
    user's file named as a catalogue vehicle), with ``-abs`` or ``-noabs`` when the run's ABS
    (``params``) differs from the vehicle file's own, for its braking limit differs
    (``offline.braking``)."""
    name = vehicle_name(vehicle) + ("-file" if shadows_catalogue(vehicle) else "")
    if params is None or params.abs_fitted == load_vehicle(vehicle).abs_fitted:
        return name
    return f"{name}-{'abs' if params.abs_fitted else 'noabs'}"


def vehicle_tables_dir(
    vehicle: str = DEFAULT_VEHICLE, base: Path | None = None, params: VehicleParams | None = None
) -> Path:
    """The tables folder of ``vehicle`` (module docstring): ``base`` (default
    ``offline.tables.default_tables_dir()``) for the default vehicle as its file has it, else
    ``base/<tables_name>``."""
    folder = Path(base) if base is not None else default_tables_dir()
    name = tables_name(vehicle, params)
    return folder if name == DEFAULT_VEHICLE else folder / name


def build_command(vehicle: str, params: VehicleParams, folder: Path) -> str:
    """The command that builds the tables ``vehicle_tables`` looks for."""
    command = f"eoam-sumo tables --vehicle {vehicle}"
    if tables_name(vehicle, params) != tables_name(vehicle):
        command += " --abs " + ("on" if params.abs_fitted else "off")
    return f"{command} --out {folder}"


def vehicle_tables(
    vehicle: str, params: VehicleParams, base: Path | None = None, cached: bool = True
) -> LookupTables:
    """The lookup tables of ``vehicle`` (its parameters ``params``) under ``base``;
    ``InputError`` in one line when its folder holds none or tables built for other
    parameters."""
    folder = vehicle_tables_dir(vehicle, base, params)
    if (
        folder != vehicle_tables_dir(DEFAULT_VEHICLE, base)
        and not (folder / METADATA_NAME).is_file()
    ):
        raise InputError(
            f"{folder}: no lookup tables for vehicle {vehicle!r}; build them with "
            f"`{build_command(vehicle, params, folder)}`"
        )
    if cached:
        return LookupTables.cached(folder, params=params)
    return LookupTables.load(folder, params=params)


class RolloverLimits(NamedTuple):
    """The four tyres' normal loads as affine functions of the plant's load accelerations,
    ``load_i = static_n[i] + per_ax[i] * ax + per_ay[i] * ay`` [N, N s^2/m] (``TYRES``
    order), and the static stability limit of ``|ay|`` [m/s^2]."""

    static_n: tuple[float, float, float, float]
    per_ax: tuple[float, float, float, float]
    per_ay: tuple[float, float, float, float]
    ssf_ay_mps2: float


def rollover_limits(params: VehicleParams) -> RolloverLimits:
    """The limits of ``params``: the plant's own ``tyre_loads_n`` evaluated at three load
    accelerations (it is affine in them until a load reaches zero, where it is clamped; the
    unit accelerations used here leave every load of a road vehicle far from zero)."""

    def loads(ax: float, ay: float) -> tuple[float, ...]:
        x = [0.0] * len(STATE_NAMES)
        x[AX_LOAD], x[AY_LOAD] = ax, ay
        return tuple(float(v) for v in tyre_loads_n(x, params, FLOAT_OPS))

    static, along, across = loads(0.0, 0.0), loads(1.0, 0.0), loads(0.0, 1.0)
    h = params.cg_height_m
    return RolloverLimits(
        _four(static, (0.0,) * 4),
        _four(along, static),
        _four(across, static),
        G_MPS2 * params.track_m / (2.0 * h) if h > 0.0 else math.inf,
    )


def _four(a: tuple[float, ...], b: tuple[float, ...]) -> tuple[float, float, float, float]:
    """The four tyres' ``a - b``."""
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2], a[3] - b[3])
