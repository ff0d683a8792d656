"""The offline tables at run time: loading, the metadata check and fast interpolation.

Files (written by ``build.build_tables``): ``phase_boundaries.csv`` (DMM boundaries per
friction and relative speed), ``lookup_tables.npz`` (the 3D lookup tables of sec. 8.2:
differential x-distance x entry speed x friction) and ``metadata.json``.

Interpolation rules:

- friction: linear between the grid frictions; below the lowest the tables do not apply
  (``check_run`` raises ``InputError``), above the highest the highest is used (a grippier
  surface needs less distance, so this is conservative); linear interpolation of the convex
  1/mu-like boundaries overestimates them between grid frictions (conservative too);
- boundaries in relative speed: linear within the grid; below the lowest grid speed the
  braking boundaries' closed forms (``PhaseBoundaries._below_grid``: B0 = v^2 / (2 a),
  Bb = B0 + t_b v + c_b), the clearing boundaries scaled linearly to 0 at zero closing speed
  (nothing to avoid), the TTC kept;
  clamped to the top row above the highest (only an obstacle moving towards the ego closes
  faster than the ego drives, and runs above the grid are refused by ``check_run``);
- trajectories in entry speed: linear within the grid, clamped to the lowest grid speed below
  it (never read there: ``EoamSettings.min_steer_speed_mps`` brakes a STEER sector below
  20 km/h of ego speed, and a lane change's entry speed is the ego's) and to
  the highest above it (``check_run`` refuses runs above the grid);
- in differential x: linear between the rows of the uniform grid; before 0 the first row,
  past the manoeuvre's end the final values (y = h, ax = 0, yaw = 0, curvature = 0, steer 0).
"""

from __future__ import annotations

import bisect
import csv
import hashlib
import json
import math
import os
from pathlib import Path
from typing import NamedTuple, cast

import numpy as np

from eoam_sumo.errors import InputError
from eoam_sumo.manoeuvre.points import TrajectoryPoint
from eoam_sumo.offline.boundaries import max_decel_no_lock_mps2
from eoam_sumo.params import VehicleParams, describe, ego_e_class_sedan
from eoam_sumo.textfiles import not_utf8

CSV_NAME = "phase_boundaries.csv"
NPZ_NAME = "lookup_tables.npz"
METADATA_NAME = "metadata.json"
FORMAT_VERSION = 2
#: The lowest entry speed a run may have [km/h] (the design range's floor); below the tables'
#: lowest speed the DMM only brakes: no lane change is offered there.
MIN_ENTRY_SPEED_KMH = 5.0
TABLE_NAMES = ("y_m", "ax_mps2", "yaw_rad", "curvature_1pm", "steer_rad", "sideslip_rad")
BOUNDARY_COLUMNS = (
    "stop_distance_m",
    "stop_distance_buffered_m",
    "clear_distance_const_m",
    "clear_distance_opt_m",
    "clear_distance_buffered_m",
    "ttc_s",
)


def entry_speed_range_mps(speed_grid_mps) -> tuple[float, float]:
    """The entry speeds a run may have on tables of this speed grid [m/s]: from
    ``MIN_ENTRY_SPEED_KMH`` (or the grid's lowest, if lower) to the grid's highest."""
    return min(MIN_ENTRY_SPEED_KMH / 3.6, speed_grid_mps[0]), speed_grid_mps[-1]


def default_tables_dir() -> Path:
    """``$EOAM_TABLES_DIR`` if set, else the repository's ``tables/``."""
    env = os.environ.get("EOAM_TABLES_DIR")
    if env:
        return Path(env)
    return Path(__file__).resolve().parents[2] / "tables"


class Boundary(NamedTuple):
    """DMM boundaries at one friction and relative speed (m, and the TTC in s)."""

    stop_m: float
    stop_buffered_m: float
    clear_const_m: float
    clear_opt_m: float
    clear_buffered_m: float
    ttc_s: float


def _bracket(grid: list, value: float) -> tuple[int, int, float]:
    """Indices and weight of ``value`` in an increasing grid, clamped at both ends."""
    if value <= grid[0]:
        return 0, 0, 0.0
    if value >= grid[-1]:
        n = len(grid) - 1
        return n, n, 0.0
    j = bisect.bisect_right(grid, value)
    return j - 1, j, (value - grid[j - 1]) / (grid[j] - grid[j - 1])


class PhaseBoundaries:
    """The DMM boundaries of ``phase_boundaries.csv`` with bilinear interpolation."""

    def __init__(self, mu_grid, speed_grid_mps, rows):
        self.mu_grid = tuple(mu_grid)  # increasing
        self.speed_grid_mps = tuple(speed_grid_mps)  # increasing
        self._mus = list(self.mu_grid)
        self._speeds = list(self.speed_grid_mps)
        self._rows = rows  # rows[i_mu][i_speed] = tuple of BOUNDARY_COLUMNS

    @classmethod
    def load(cls, directory) -> PhaseBoundaries:
        """Read ``phase_boundaries.csv`` (``#`` lines are comments)."""
        path = Path(directory) / CSV_NAME
        try:
            text = path.read_text(encoding="utf-8")
        except OSError as exc:
            raise InputError(
                f"{path}: cannot read the phase boundaries ({exc.strerror}); run `eoam-sumo tables`"
            ) from None
        except UnicodeDecodeError as exc:
            raise not_utf8(path, exc, "phase boundaries") from None
        lines = [ln for ln in text.splitlines() if ln and not ln.startswith("#")]
        table: dict[float, dict[float, tuple]] = {}
        try:
            for rec in csv.DictReader(lines):
                mu = float(rec["mu"])
                speed = float(rec["speed_kmh"]) / 3.6
                row = tuple(float(rec[c]) for c in BOUNDARY_COLUMNS)
                table.setdefault(mu, {})[speed] = row
                _check_finite_row(path, rec, (mu, speed, *row))
        except InputError:
            raise
        except (KeyError, ValueError, TypeError) as exc:
            raise InputError(f"{path}: malformed phase boundaries ({exc})") from None
        mus = sorted(table)
        if not mus:
            raise InputError(f"{path}: no phase boundaries")
        speeds = sorted(table[mus[0]])
        if any(sorted(table[mu]) != speeds for mu in mus):
            raise InputError(f"{path}: every friction must have the same speed grid")
        rows = [[table[mu][v] for v in speeds] for mu in mus]
        return cls(mus, speeds, rows)

    def _row(self, i_mu: int, i_v: int, j_v: int, w_v: float) -> list:
        a, b = self._rows[i_mu][i_v], self._rows[i_mu][j_v]
        return [x + w_v * (y - x) for x, y in zip(a, b)]

    def at(self, mu: float, rel_speed_mps: float) -> Boundary:
        """Boundaries at this friction and relative (closing) speed; see the module rules."""
        i_m, j_m, w_m = _bracket(self._mus, mu)
        speeds = self._speeds
        if rel_speed_mps < speeds[0]:
            return self._below_grid(i_m, j_m, w_m, max(rel_speed_mps, 0.0))
        i_v, j_v, w_v = _bracket(speeds, rel_speed_mps)
        lo = self._row(i_m, i_v, j_v, w_v)
        if j_m != i_m:
            hi = self._row(j_m, i_v, j_v, w_v)
            lo = [x + w_m * (y - x) for x, y in zip(lo, hi)]
        return Boundary(*lo)

    def _below_grid(self, i_m: int, j_m: int, w_m: float, v: float) -> Boundary:
        """Below the lowest grid closing speed: B0 = v^2 / (2 a) (eq. 33) with the
        deceleration a of the lowest row, Bb = B0 + t_b v + c_b (sec. 6.2) with t_b, c_b from
        the two lowest rows (Bb - B0 is linear in v); the clearing boundaries, which have no
        closed form, scaled linearly to 0 from the lowest row (nothing closes, nothing to
        avoid); TTC kept. Linear in mu between the grid frictions, as within the grid. (Below
        20 km/h of ego speed the EOAM only brakes: ``EoamSettings.min_steer_speed_mps``.)"""
        lo, hi = (self._low_speed_row(i, v) for i in (i_m, j_m))
        return Boundary(*(a + w_m * (b - a) for a, b in zip(lo, hi)))

    def _low_speed_row(self, i_mu: int, v: float) -> tuple[float, ...]:
        """(B0, Bb, S, S*, Sb, TTC) of friction row ``i_mu`` at a speed v below the grid."""
        rows, speeds = self._rows[i_mu], self._speeds
        v0, (stop0, buffered0, clear, clear_opt, clear_b, ttc) = speeds[0], rows[0]
        t_b = 0.0
        if len(speeds) > 1:
            t_b = ((rows[1][1] - rows[1][0]) - (buffered0 - stop0)) / (speeds[1] - v0)
        c_b = buffered0 - stop0 - t_b * v0
        stop = stop0 * (v / v0) ** 2  # v^2 / (2 a) with a = v0^2 / (2 B0(v0))
        scale = v / v0
        return (stop, stop + t_b * v + c_b, clear * scale, clear_opt * scale, clear_b * scale, ttc)


class Trajectory:
    """One manoeuvre's reference, blended once at the trigger; ``at(dx)`` is pure arithmetic."""

    __slots__ = ("_cols", "_final", "_inv_step", "_last", "length_m")

    def __init__(self, length_m: float, step_m: float, columns: np.ndarray, final: TrajectoryPoint):
        self.length_m = float(length_m)
        self._inv_step = 1.0 / step_m
        self._last = columns.shape[1] - 1
        self._cols = tuple(c.tolist() for c in columns)
        self._final = final

    def at(self, dx_m: float) -> TrajectoryPoint:
        """The trajectory at differential x ``dx_m``."""
        f = dx_m * self._inv_step
        if f <= 0.0:
            return TrajectoryPoint(*(c[0] for c in self._cols))
        i = int(f)
        if i >= self._last:
            return self._final
        w = f - i
        return TrajectoryPoint(*(c[i] + w * (c[i + 1] - c[i]) for c in self._cols))


_LOADED: dict[tuple, LookupTables] = {}  # LookupTables.cached: (folder, params, stamps) ->
_LOADED_MAX = 4


class LookupTables:
    """The 3D lookup tables and the phase boundaries of one build."""

    def __init__(
        self, arrays: dict, boundaries: PhaseBoundaries, metadata: dict, params: VehicleParams
    ):
        self.mu_grid = tuple(float(m) for m in arrays["mu_grid"])  # increasing
        self.speed_grid_mps = tuple(float(v) for v in arrays["speed_grid_mps"])  # increasing
        self.dx_step_m = float(arrays["dx_step_m"])
        self.lane_change_m = float(arrays["lane_change_m"])
        self.length_m = np.asarray(arrays["length_m"], dtype=float)  # (n_mu, n_speed)
        self._tables = np.stack([np.asarray(arrays[n], dtype=float) for n in TABLE_NAMES])
        self.length_m.flags.writeable = self._tables.flags.writeable = False  # shared: cached
        self.boundaries = boundaries
        self.metadata = metadata
        self.params = params
        self._mus = list(self.mu_grid)
        self._speeds = list(self.speed_grid_mps)
        braking = metadata.get("braking", {})
        self._braking_mus = [float(m) for m in braking.get("mu", [])]
        self._braking_decels = [float(a) for a in braking.get("decel_mps2", [])]
        # tables from before the setting: B0 at eq. 33's deceleration itself
        share = metadata.get("design", {}).get("limit_brake_fraction", {}).get("value", 1.0)
        self.limit_brake_fraction = float(share)

    @classmethod
    def load(cls, directory=None, params: VehicleParams | None = None) -> LookupTables:
        """Load a tables folder; refuse it (``InputError``) if built for other parameters."""
        folder = Path(directory) if directory is not None else default_tables_dir()
        params = params or ego_e_class_sedan()
        meta_path = folder / METADATA_NAME
        try:
            metadata = json.loads(meta_path.read_text(encoding="utf-8"))
        except UnicodeDecodeError as exc:
            raise not_utf8(meta_path, exc, "tables' metadata") from None
        except OSError as exc:
            raise InputError(
                f"{meta_path}: cannot read the tables' metadata ({exc.strerror}); "
                "run `eoam-sumo tables`"
            ) from None
        except json.JSONDecodeError as exc:
            raise InputError(
                f"{meta_path}: malformed JSON ({exc.msg}, line {exc.lineno})"
            ) from None
        _check_metadata(meta_path, metadata, params)
        npz_path = folder / NPZ_NAME
        try:
            with np.load(npz_path) as data:
                arrays = {k: data[k] for k in data.files}
        except (OSError, ValueError) as exc:
            raise InputError(
                f"{npz_path}: cannot read the lookup tables ({exc}); run `eoam-sumo tables`"
            ) from None
        missing = [
            k
            for k in (
                *TABLE_NAMES,
                "mu_grid",
                "speed_grid_mps",
                "dx_step_m",
                "length_m",
                "lane_change_m",
            )
            if k not in arrays
        ]
        if missing:
            raise InputError(
                f"{npz_path}: missing arrays {', '.join(missing)}; run `eoam-sumo tables`"
            )
        for name, array in arrays.items():
            if array.dtype.kind == "f" and not np.isfinite(array).all():
                raise InputError(
                    f"{npz_path}: array {name} holds a NaN or an infinity; run `eoam-sumo tables`"
                )
        boundaries = PhaseBoundaries.load(folder)
        _check_same_grids(folder, metadata, arrays, boundaries)
        return cls(arrays, boundaries, metadata, params)

    @classmethod
    def cached(cls, directory=None, params: VehicleParams | None = None) -> LookupTables:
        """:meth:`load`, kept for the process while the folder's files are unchanged (their
        size and modification time): a batch worker runs many cases on the same tables, and
        reading them (the npz decompressed, the csv parsed) again for each would be waste."""
        folder = Path(directory) if directory is not None else default_tables_dir()
        params = params or ego_e_class_sedan()
        try:
            stamp = tuple(
                (st.st_size, st.st_mtime_ns)
                for st in (os.stat(folder / name) for name in (METADATA_NAME, NPZ_NAME, CSV_NAME))
            )
        except OSError:
            return cls.load(folder, params)  # says which file is missing
        key = (str(folder.resolve()), params, stamp)
        tables = _LOADED.get(key)
        if tables is None:
            tables = cls.load(folder, params)
            if len(_LOADED) >= _LOADED_MAX:
                _LOADED.pop(next(iter(_LOADED)))
            _LOADED[key] = tables
        return tables

    def entry_speed_range_mps(self) -> tuple[float, float]:
        """The entry speeds a run may have [m/s] (what ``check_run`` accepts)."""
        return entry_speed_range_mps(self.speed_grid_mps)

    def check_run(self, mu: float, speed_mps: float) -> None:
        """Refuse (``InputError``) a run the tables do not cover: entry speed below
        ``MIN_ENTRY_SPEED_KMH`` or above the grid, or friction below the grid (above it the
        highest friction's tables are used: they ask for less than the road gives). Below the
        grid's lowest speed the DMM only brakes (``PhaseBoundaries._below_grid``)."""
        low, top = entry_speed_range_mps(self.speed_grid_mps)
        if not low - 1e-9 <= speed_mps <= top + 1e-9:
            raise InputError(
                f"ego speed {speed_mps * 3.6:.1f} km/h is outside the design range "
                f"[{low * 3.6:.0f}, {top * 3.6:.0f}] km/h (the top is the tables'; rebuild "
                "with `eoam-sumo tables --speeds-kmh ...` to go higher)"
            )
        if mu < self.mu_grid[0] - 1e-9:
            raise InputError(
                f"mu {mu:g} is below the tables' lowest friction "
                f"{self.mu_grid[0]:g}; rebuild with `eoam-sumo tables --mu ...`"
            )

    def max_decel_mps2(self, mu: float) -> float:
        """Eq. 33's braking deceleration at this friction: the largest without locking an
        axle, or with ABS what the vehicle's ABS achieves (the build's values per grid
        friction in metadata.json, linear in mu between them, clamped outside)."""
        mu = min(mu, self.mu_grid[-1])
        if not self.params.abs_fitted:
            return max_decel_no_lock_mps2(self.params, mu)
        i, j, w = _bracket(self._braking_mus, mu)
        return self._braking_decels[i] + w * (self._braking_decels[j] - self._braking_decels[i])

    def limit_brake_decel_mps2(self, mu: float) -> float:
        """The deceleration of limit braking, whose stopping distance is the tables' B0: the
        design's ``limit_brake_fraction`` of eq. 33's (``max_decel_mps2``)."""
        return self.limit_brake_fraction * self.max_decel_mps2(mu)

    def trajectory(self, mu: float, speed_mps: float) -> Trajectory:
        """The manoeuvre reference for this friction and entry speed (bilinear blend, once)."""
        i_m, j_m, w_m = _bracket(self._mus, mu)
        i_v, j_v, w_v = _bracket(self._speeds, speed_mps)
        corners = (
            (i_m, i_v, (1 - w_m) * (1 - w_v)),
            (i_m, j_v, (1 - w_m) * w_v),
            (j_m, i_v, w_m * (1 - w_v)),
            (j_m, j_v, w_m * w_v),
        )
        lengths = self.length_m
        rows = int(max(lengths[m, v] for m, v, _ in corners) / self.dx_step_m) + 3
        rows = min(rows, self._tables.shape[-1])
        cols = cast(np.ndarray, sum(c * self._tables[:, m, v, :rows] for m, v, c in corners))
        length = sum(c * lengths[m, v] for m, v, c in corners)
        final = TrajectoryPoint(self.lane_change_m, 0.0, 0.0, 0.0, 0.0, 0.0)
        return Trajectory(length, self.dx_step_m, cols, final)


def _check_finite_row(path: Path, rec: dict, values: tuple) -> None:
    """InputError naming the friction, speed and column of a non-finite phase boundary."""
    if all(math.isfinite(v) for v in values):
        return
    column = next(
        c for c in ("mu", "speed_kmh", *BOUNDARY_COLUMNS) if not math.isfinite(float(rec[c]))
    )
    raise InputError(
        f"{path}: malformed phase boundaries (column {column} is {rec[column]} at mu "
        f"{rec['mu']}, speed {rec['speed_kmh']} km/h)"
    )


def _check_same_grids(folder: Path, metadata: dict, arrays: dict, boundaries) -> None:
    """The three files of a tables folder were built together: the same friction and speed
    grids in metadata.json, the lookup tables and the phase boundaries."""
    grids = metadata.get("grids", {})
    try:
        mus = sorted(float(m) for m in grids["mu"])
        speeds = sorted(float(v) / 3.6 for v in grids["speed_kmh"])
    except (KeyError, TypeError, ValueError):
        raise InputError(
            f"{folder / METADATA_NAME}: no friction and speed grids; run `eoam-sumo tables`"
        ) from None
    for name, mu_grid, speed_grid in (
        (NPZ_NAME, arrays["mu_grid"], arrays["speed_grid_mps"]),
        (CSV_NAME, boundaries.mu_grid, boundaries.speed_grid_mps),
    ):
        if not (_same(mu_grid, mus, 1e-9) and _same(speed_grid, speeds, 1e-6)):
            raise InputError(
                f"{folder}: {name} holds other friction or speed grids than "
                f"{METADATA_NAME}: the folder mixes two builds; run `eoam-sumo "
                "tables`"
            )


def _same(grid, values: list[float], tol: float) -> bool:
    return len(grid) == len(values) and bool(np.allclose(sorted(grid), values, atol=tol))


DESIGN_FIELDS = (
    "mass_kg",
    "yaw_inertia_kgm2",
    "cg_to_front_m",
    "cg_to_rear_m",
    "cg_height_m",
    "width_m",
    "front_overhang_m",
    "max_steer_rad",
    "max_steer_rate_radps",
    "cornering_stiffness_front_npr",
    "cornering_stiffness_rear_npr",
    "slip_angle_sat_rad",
    "max_drive_force_n",
    "max_drive_power_w",
    "max_brake_force_n",
    "brake_front_share",
)
"""The vehicle parameters the offline design uses (``offline/``: the design model, the
inverse dynamics, the boundaries): the tables are valid for a vehicle that matches them. The
chassis-only fields (tyre, wheels, ESC, drivetrain) do not change them, except with ABS:
its braking limit comes from the whole plant (``braking.abs_decel_mps2``), so the tables of a
vehicle with ABS are valid only for the same digest of every parameter but ESC's
(``vehicle_digest``)."""

BUILD_COMMAND = "eoam-sumo tables --vehicle NAME|FILE [--abs on|off] --out DIR"


def vehicle_digest(params: VehicleParams) -> str:
    """SHA-256 (16 hex digits) of every parameter value of the vehicle but its name and its ESC
    (which does not act in the straight stop that measures the ABS braking limit)."""
    values = {
        k: v["value"]
        for k, v in describe(params).items()
        if k != "name" and not k.startswith("esc_")
    }
    text = json.dumps(values, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _check_metadata(path: Path, metadata: dict, params: VehicleParams) -> None:
    if metadata.get("format") != FORMAT_VERSION:
        raise InputError(
            f"{path}: tables format {metadata.get('format')!r} is not "
            f"{FORMAT_VERSION}; run `{BUILD_COMMAND}`"
        )
    stored = metadata.get("vehicle", {})
    wanted = describe(params)
    stored = {"abs_fitted": {"value": False}, **stored}  # tables built before ABS existed
    diffs = [
        f"{n} (tables {stored.get(n, {}).get('value')!r}, in use {wanted[n]['value']!r})"
        for n in (*DESIGN_FIELDS, "abs_fitted")
        if not isinstance(stored.get(n), dict) or stored[n].get("value") != wanted[n]["value"]
    ]
    if not diffs and params.abs_fitted:
        digest = metadata.get("vehicle_digest")
        if digest != vehicle_digest(params) or not metadata.get("braking", {}).get("mu"):
            diffs = [f"parameter digest (tables {digest!r}, in use {vehicle_digest(params)!r})"]
    if diffs:
        built = stored.get("name", {}).get("value", "an unnamed vehicle")
        raise InputError(
            f"{path}: the tables were built for {built!r}, not for {params.name!r} "
            f"({', '.join(diffs[:3])}); build its tables with `{BUILD_COMMAND}`"
        )
