"""The task a batch worker runs: one matrix case through the co-simulation.

Kept apart from the runner so a worker process imports only what a case needs.
"""

from __future__ import annotations

import tempfile
from dataclasses import asdict, dataclass, fields, replace
from pathlib import Path
from typing import TYPE_CHECKING, get_type_hints

from eoam_sumo.matrix import Case, vehicle_params
from eoam_sumo.params import VehicleParams
from eoam_sumo.sim.settings import REFERENCE_SUMO_STEP_S
from eoam_sumo.vehicle_files import DEFAULT_VEHICLE

if TYPE_CHECKING:
    from eoam_sumo.sim.settings import RunSettings

#: The files a case writes (``sim.runlog.write_run``), in the order they are written, by
#: ``--timeseries`` format.
TIMESERIES_FORMATS = ("csv", "parquet", "none")
CASE_FILES_OF = {
    "csv": ("timeseries.csv", "traffic.csv", "road.csv", "summary.json"),
    "parquet": ("timeseries.parquet", "traffic.parquet", "road.csv", "summary.json"),
    "none": ("summary.json",),
}
ALL_CASE_FILES = (
    "timeseries.csv",
    "timeseries.parquet",
    "traffic.csv",
    "traffic.parquet",
    "road.csv",
    "summary.json",
)
#: Modules a worker imports before its first case, so start-up is not charged to a case:
#: the co-simulation, SUMO's library and the root finders of the quintic shift (which
#: imports them at its first use, so that the command line's process never does).
PRELOAD = ("eoam_sumo.sim.cosim", "libsumo", "scipy.optimize")


@dataclass(frozen=True)
class CaseTask:
    """One case to run. ``case_dir`` None: run in a scratch folder and return the files'
    bytes (for Dask workers that may not share the client's file system)."""

    case: Case
    case_dir: Path | None
    tables_dir: Path | None = None
    timeseries: str = "csv"  # csv, parquet or none


@dataclass(frozen=True)
class CaseParameters:
    """A case's matrix parameters as stored with its summary (summary.json's ``case``) and in
    results.csv (``sumocfg`` among the last columns there)."""

    case_id: str
    ego_speed_kmh: float
    # the friction asked for, None: each lane's own (the summary's ``mu`` is the one under
    # the ego at its start, results.csv's ``mu_at_start``)
    mu: float | None
    oncoming_start_m: float | None  # None: no oncoming car added
    aro_hold_s: float | None  # None: the route file's value
    aro_decel_mps2: float | None  # None: the route file's value
    max_time_s: float
    radar_range_m: float | None  # None: the radar's default range
    policy: str  # the decision policy: paper or safe
    driver: str  # the ego's controller: eoam or a reference driver
    v2x_range_m: float  # 0: no V2X
    v2x_latency_s: float
    v2x_loss: float
    v2x_penetration: float
    mu_belief: str | float  # known, estimate or a number
    radar_model: str  # ideal or automotive
    seed: int
    after_stop_s: float | None  # None: the run's default
    sumo_step_s: float  # SUMO's step the case ran at [s]
    road: str | None  # a generated scenario (None: the sumocfg's): rural or motorway
    los: str | None  # its level of service
    lanes: int | None
    speed_limit_kmh: float | None
    curve_radius_m: float | None
    vehicle: str  # the ego's: a catalogue name or a vehicle file
    draw: int | None  # the sample's number in a sampled matrix
    sumocfg: str  # a generated scenario's: relative to the case folder

    @classmethod
    def of(cls, case: Case) -> CaseParameters:
        own = ("sumocfg", "vehicle", "sumo_step_s")
        return cls(
            **{f.name: getattr(case, f.name) for f in fields(cls) if f.name not in own},
            sumocfg=str(case.sumocfg),
            vehicle=case.vehicle or DEFAULT_VEHICLE,
            sumo_step_s=case.sumo_step_s or REFERENCE_SUMO_STEP_S,  # the step the case ran
        )


#: The parameter names, in order.
PARAMETERS: tuple[str, ...] = tuple(f.name for f in fields(CaseParameters))
#: The parameters that are numbers (or empty).
NUMERIC_PARAMETERS: tuple[str, ...] = tuple(
    name
    for name, tp in get_type_hints(CaseParameters).items()
    if tp in (float, int, float | None, int | None)
)


def case_parameters(case: Case) -> dict:
    """The case's matrix parameters, stored with its summary."""
    return asdict(CaseParameters.of(case))


def case_vehicle(case: Case) -> VehicleParams:
    """The ego of a case: its vehicle (none named: the paper's sedan), its ABS and ESC
    switched as the case asks."""
    return vehicle_params(case.vehicle, case.abs_fitted, case.esc_fitted)


def case_settings(task: CaseTask) -> RunSettings:
    """The ``RunSettings`` of a case: its vehicle, policy, V2X link, radar range and whether
    the EOAM may steer (``Case.steering_inhibited``)."""
    from eoam_sumo.sensing.radar import RadarSettings
    from eoam_sumo.sim.cosim import policy_settings
    from eoam_sumo.sim.settings import RunSettings

    case = task.case
    settings = policy_settings(
        RunSettings(
            max_time_s=case.max_time_s,
            tables_dir=task.tables_dir,
            mu_belief=case.mu_belief,
            radar_model=case.radar_model,
            seed=case.seed,
            after_stop_s=case.after_stop_s,
            sumo_step_s=case.sumo_step_s,
            driver=case.driver,
            vehicle=case_vehicle(case),
            vehicle_id=case.vehicle or DEFAULT_VEHICLE,
        ),
        case.policy,
        case.v2x_range_m,
        case.v2x_latency_s,
        case.v2x_loss,
        case.v2x_penetration,
    )
    if case.radar_range_m is not None:
        settings = replace(settings, radar=RadarSettings(range_m=case.radar_range_m))
    if case.steering_inhibited:
        settings = replace(settings, eoam=replace(settings.eoam, steering_inhibited=True))
    return settings


def run_matrix_case(task: CaseTask) -> dict:
    """Run the case; ``{"summary": dict, "files": {name: bytes} or None}``.

    Old output files of the case are removed first, so a folder never mixes runs.
    """
    from eoam_sumo.sim.cosim import run_case

    case = task.case
    settings = case_settings(task)
    extra = {"case": case_parameters(case)}
    if task.case_dir is not None:
        case_dir = Path(task.case_dir)
        case_dir.mkdir(parents=True, exist_ok=True)
        for name in ALL_CASE_FILES:
            (case_dir / name).unlink(missing_ok=True)
        summary = run_case(
            _scenario(case, case_dir),
            case.overrides(),
            case_dir,
            settings,
            extra=extra,
            timeseries=task.timeseries,
        )
        return {"summary": summary, "files": None}
    with tempfile.TemporaryDirectory(prefix="eoam-case-") as scratch:
        summary = run_case(
            _scenario(case, Path(scratch)),
            case.overrides(),
            Path(scratch),
            settings,
            extra=extra,
            timeseries=task.timeseries,
        )
        files = {
            name: (Path(scratch) / name).read_bytes() for name in CASE_FILES_OF[task.timeseries]
        }
    return {"summary": summary, "files": files}


def _scenario(case: Case, case_dir: Path) -> Path:
    """The case's sumocfg; a generated scenario written first into ``case_dir`` (its
    ``case.sumocfg`` there, the traffic seeded with the case's seed)."""
    spec = case.traffic()
    if spec is None:
        return case.sumocfg
    from eoam_sumo.traffic_levels.build import write_scenario

    return write_scenario(spec, case_dir / case.sumocfg.parent)
