"""Build the offline tables: optimal lane changes over speed x friction, checked, tabulated.

One warm-start chain per friction (``ocp.solve_chain``, highest speed first), so the results do
not depend on the number of parallel jobs; frictions run in parallel in ``spawn`` processes.
Each solution is re-simulated and audited (``resim``); the audited re-simulation gives the
clearing distance (eqs. 30-32) and the lookup-table rows (sec. 8.2). Files are written only
after every solve succeeded, each atomically.
"""

from __future__ import annotations

import csv
import io
import json
import math
import multiprocessing
import queue as queue_module
import sys
import zipfile
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from dataclasses import dataclass, replace
from pathlib import Path

import casadi
import numpy as np
from tqdm import tqdm

import eoam_sumo
from eoam_sumo.errors import InputError
from eoam_sumo.fileio import write_atomic
from eoam_sumo.offline import tables as tb
from eoam_sumo.offline.boundaries import (
    clearing_distance_m,
    constant_speed_clearing_distance_m,
    steer_buffered_m,
    stop_buffered_m,
)
from eoam_sumo.offline.braking import braking_decel_mps2, braking_model, braking_stop_m
from eoam_sumo.offline.design import DesignSettings
from eoam_sumo.offline.ocp import LaneChangeOcp, solve_chain, solver_options
from eoam_sumo.offline.resim import Resimulation, audit, resimulate
from eoam_sumo.params import VehicleParams, aro_d_class_minivan, describe, ego_e_class_sedan

#: phase_boundaries.csv: the grid point, the boundaries the tables read, then the rest
CSV_COLUMNS = (
    "mu",
    "speed_kmh",
    *tb.BOUNDARY_COLUMNS,
    "max_decel_mps2",
    "manoeuvre_length_m",
    "manoeuvre_time_s",
    "exit_speed_mps",
)
_CSV_FORMATS = (
    "{:.2f}",
    "{:.1f}",
    "{:.4f}",
    "{:.4f}",
    "{:.4f}",
    "{:.4f}",
    "{:.4f}",
    "{:.3f}",
    "{:.4f}",
    "{:.4f}",
    "{:.4f}",
    "{:.4f}",
)
EXTRA_TABLES = ("speed_mps",)  # stored for reference and plots, not interpolated at run time


@dataclass(frozen=True)
class SpeedResult:
    """Everything one optimal lane change contributes to the tables."""

    mu: float
    speed_mps: float
    csv_values: tuple  # in CSV_COLUMNS order
    length_m: float
    rows: np.ndarray  # (len(TABLE_NAMES) + len(EXTRA_TABLES), n) on the dx grid from 0


def sample_on_grid(resim: Resimulation, step_m: float) -> np.ndarray:
    """Lookup-table rows on the uniform differential-x grid up to the manoeuvre end.

    Path y; body longitudinal acceleration (eq. 1); path yaw theta = atan2(y', x') (eq. 10);
    signed path curvature (x' y'' - y' x'') / |v|^3 (eq. 9); steering angle; body sideslip
    (course less body yaw); speed.
    """
    s = resim.states
    x, vx, vy, yaw = s[:, 0], s[:, 1], s[:, 3], s[:, 4]
    ax_g = resim.ax_body_mps2 * np.cos(yaw) - resim.ay_body_mps2 * np.sin(yaw)
    ay_g = resim.ax_body_mps2 * np.sin(yaw) + resim.ay_body_mps2 * np.cos(yaw)
    speed = np.hypot(vx, vy)
    course = np.arctan2(vy, vx)
    quantities = (
        s[:, 2],
        resim.ax_body_mps2,
        course,
        (vx * ay_g - vy * ax_g) / speed**3,
        s[:, 6],
        course - yaw,
        speed,
    )
    grid = np.arange(0.0, x[-1] + 1e-9, step_m)
    return np.stack([np.interp(grid, x, q) for q in quantities])


def _solve_friction(
    params: VehicleParams, settings: DesignSettings, mu: float, progress_queue=None
) -> list[SpeedResult]:
    """One friction's chain, audited and reduced to table rows (runs in a worker process)."""
    ocp = LaneChangeOcp(params, settings)
    decel = braking_decel_mps2(params, mu)
    ttc = settings.ttc_s(mu)
    results = []

    def on_solved(sol):
        resim = resimulate(sol, params, 0.5 * settings.dx_step_m)
        audit(sol, resim, params, settings)
        v = sol.speed_mps
        stop = braking_stop_m(params, mu, v, settings.limit_brake_fraction)
        clear_opt = clearing_distance_m(
            resim.states[:, 0],
            resim.states[:, 2],
            resim.states[:, 4],
            params,
            settings.obstacle_width_m,
        )
        clear_const = constant_speed_clearing_distance_m(v, mu, params, settings)
        values = (
            mu,
            v * 3.6,
            stop,
            stop_buffered_m(stop, v, settings),
            clear_const,
            clear_opt,
            steer_buffered_m(clear_opt, v, settings),
            ttc,
            decel,
            resim.distance_m,
            sol.duration_s,
            float(np.hypot(resim.states[-1, 1], resim.states[-1, 3])),
        )
        results.append(
            SpeedResult(mu, v, values, resim.distance_m, sample_on_grid(resim, settings.dx_step_m))
        )
        if progress_queue is not None:
            progress_queue.put(1)

    speeds = [v / 3.6 for v in settings.speeds_kmh]
    solve_chain(ocp, mu, speeds, on_solved)
    return sorted(results, key=lambda r: r.speed_mps)


def build_tables(
    out_dir,
    jobs: int = 1,
    speeds_kmh=None,
    mus=None,
    progress: bool = True,
    params: VehicleParams | None = None,
    settings: DesignSettings | None = None,
) -> Path:
    """Build ``phase_boundaries.csv``, ``lookup_tables.npz`` and ``metadata.json`` in out_dir.

    ``speeds_kmh`` / ``mus`` replace the grids of ``settings`` (default ``DesignSettings()``:
    20-175 km/h every 5 km/h, mu 1.0, 0.7, 0.3, 0.1). Raises ``InputError`` for bad grids or
    jobs and ``ocp.OcpError`` naming the speed and friction of a failed or unchecked solve.
    """
    params = params or ego_e_class_sedan()
    settings = settings or DesignSettings()
    if not (isinstance(jobs, int) and jobs >= 1):
        raise InputError(f"jobs={jobs!r} must be an integer >= 1")
    try:
        if speeds_kmh is not None:
            settings = replace(settings, speeds_kmh=tuple(sorted(float(v) for v in speeds_kmh)))
        if mus is not None:
            settings = replace(settings, mus=tuple(float(m) for m in mus))
    except (ValueError, TypeError) as exc:
        raise InputError(f"bad tables grid: {exc}") from None
    out = Path(out_dir)
    per_mu = _run(params, settings, jobs, progress)
    out.mkdir(parents=True, exist_ok=True)
    _write_csv(out / tb.CSV_NAME, per_mu, params)
    _write_npz(out / tb.NPZ_NAME, per_mu, settings)
    _write_metadata(out / tb.METADATA_NAME, params, settings, per_mu)
    return out


def _run(params, settings, jobs, progress) -> dict:
    total = len(settings.mus) * len(settings.speeds_kmh)
    bar = tqdm(total=total, disable=not progress, file=sys.stderr, desc="EOAM tables", unit="solve")
    try:
        if jobs == 1 or len(settings.mus) == 1:
            callback = _BarQueue(bar)
            return {mu: _solve_friction(params, settings, mu, callback) for mu in settings.mus}
        ctx = multiprocessing.get_context("spawn")
        with (
            ctx.Manager() as manager,
            ProcessPoolExecutor(max_workers=min(jobs, len(settings.mus)), mp_context=ctx) as pool,
        ):
            q = manager.Queue()
            futures = {  # the lowest friction's chain (the slowest) first
                pool.submit(_solve_friction, params, settings, mu, q): mu
                for mu in sorted(settings.mus)
            }
            pending = set(futures)
            while pending:
                done, pending = wait(pending, timeout=0.2, return_when=FIRST_COMPLETED)
                _drain(q, bar)
                for f in done:
                    f.result()  # raise a worker's error now
            _drain(q, bar)
            per_mu = {mu: f.result() for f, mu in futures.items()}
            return {mu: per_mu[mu] for mu in settings.mus}
    finally:
        bar.close()


class _BarQueue:
    """In-process stand-in for the progress queue."""

    def __init__(self, bar):
        self._bar = bar

    def put(self, n):
        self._bar.update(n)


def _drain(q, bar) -> None:
    while True:
        try:
            bar.update(q.get_nowait())
        except queue_module.Empty:
            return


def _write_csv(path: Path, per_mu: dict, params: VehicleParams) -> None:
    buf = io.StringIO()
    buf.write(
        f"# eoam-sumo {eoam_sumo.__version__} DMM phase boundaries for {params.name}; "
        f"relative speed = entry speed of the lane change; see {tb.METADATA_NAME}\n"
    )
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(CSV_COLUMNS)
    for results in per_mu.values():
        for r in results:
            writer.writerow([f.format(v) for f, v in zip(_CSV_FORMATS, r.csv_values)])
    write_atomic(path, buf.getvalue().encode())


def _write_npz(path: Path, per_mu: dict, settings: DesignSettings) -> None:
    mus = sorted(per_mu)
    speeds = [r.speed_mps for r in per_mu[mus[0]]]
    step = settings.dx_step_m
    n_rows = math.ceil(max(r.length_m for rs in per_mu.values() for r in rs) / step) + 2
    names = tb.TABLE_NAMES + EXTRA_TABLES
    arrays = {n: np.zeros((len(mus), len(speeds), n_rows)) for n in names}
    lengths = np.zeros((len(mus), len(speeds)))
    for i, mu in enumerate(mus):
        for j, r in enumerate(per_mu[mu]):
            n = r.rows.shape[1]
            lengths[i, j] = r.length_m
            for k, name in enumerate(names):
                arrays[name][i, j, :n] = r.rows[k]
            arrays["y_m"][i, j, n:] = settings.lane_change_m  # final values past the end
            arrays["speed_mps"][i, j, n:] = r.rows[names.index("speed_mps"), -1]
    arrays.update(
        mu_grid=np.array(mus),
        speed_grid_mps=np.array(speeds),
        dx_step_m=np.array(step),
        length_m=lengths,
        lane_change_m=np.array(settings.lane_change_m),
    )
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", compression=zipfile.ZIP_DEFLATED) as zf:
        for name in sorted(arrays):  # fixed order and timestamps: byte-identical rebuilds
            info = zipfile.ZipInfo(name + ".npy", date_time=(1980, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            item = io.BytesIO()
            np.lib.format.write_array(item, np.array(arrays[name], order="C"), allow_pickle=False)
            zf.writestr(info, item.getvalue())
    write_atomic(path, buf.getvalue())


def _write_metadata(
    path: Path, params: VehicleParams, settings: DesignSettings, per_mu: dict
) -> None:
    mus = sorted(per_mu)
    decel_column = CSV_COLUMNS.index("max_decel_mps2")
    meta = {
        "format": tb.FORMAT_VERSION,
        "package": "eoam-sumo",
        "package_version": eoam_sumo.__version__,
        "vehicle_name": params.name,
        "vehicle_digest": tb.vehicle_digest(params),
        "vehicle": describe(params),
        "braking": {
            "model": braking_model(params),
            "mu": mus,
            "decel_mps2": [per_mu[mu][0].csv_values[decel_column] for mu in mus],
        },
        "obstacle": describe(aro_d_class_minivan()),
        "design": settings.as_dict(),
        "grids": {
            "mu": sorted(settings.mus),
            "speed_kmh": list(settings.speeds_kmh),
            "dx_step_m": settings.dx_step_m,
        },
        "solver": {
            "name": "ipopt (CasADi Opti, direct collocation)",
            "casadi_version": casadi.CasadiMeta.version(),
            "options": solver_options(settings),
            "last_resort_options": solver_options(settings, patient=True),
        },
        "files": {
            tb.CSV_NAME: "DMM phase boundaries per friction and relative speed",
            tb.NPZ_NAME: "lookup tables [mu, entry speed, dx]: "
            + ", ".join(tb.TABLE_NAMES + EXTRA_TABLES),
        },
    }
    write_atomic(path, (json.dumps(meta, indent=2, sort_keys=True) + "\n").encode())
