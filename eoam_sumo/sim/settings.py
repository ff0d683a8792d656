"""The settings of one co-simulation run: rates, the time limit, and the radar's, the EOAM's,
the friction belief's, V2X's, the corner radars' and the GUI's settings."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

from mypy_extensions import mypyc_attr

from eoam_sumo.drivers import DRIVERS
from eoam_sumo.eoam_settings import EoamSettings
from eoam_sumo.errors import InputError
from eoam_sumo.params import VehicleParams, ego_e_class_sedan
from eoam_sumo.sensing.next_lane import CornerRadarSettings
from eoam_sumo.sensing.radar import RadarSettings
from eoam_sumo.sensing.v2x import V2XSettings
from eoam_sumo.sim.session.gui import GuiSettings
from eoam_sumo.vehicle_files import DEFAULT_VEHICLE

#: A run's simulated time limit unless set [s]: every Table 2 case ends well before it (the
#: slowest, 55 km/h on mu 0.1, settles after 29.6 s).
DEFAULT_MAX_TIME_S = 60.0
#: SUMO's longest step in a multi-rate co-simulation [s] (its traffic models' default step).
MAX_SUMO_STEP_S = 0.1
#: SUMO's step of the reference run [s]: one rate with the control step (``run``, the golden).
REFERENCE_SUMO_STEP_S = 0.01
#: SUMO's step for studies (``batch``, ``protocol``) unless ``--sumo-step-s`` or the matrix's
#: ``[scenario] sumo_step_s`` sets one [s]: the longest step at which Table 2 keeps the
#: reference's colours and contact partners and its figures within the golden tolerances
#: (``tests/golden/step_check.py``; docs/performance.md).
STUDY_SUMO_STEP_S = 0.05
#: The longest simulated time limit accepted [s]: a day of traffic (a larger one only
#: overflows the step count; 1e308 did).
MAX_TIME_LIMIT_S = 86400.0


def check_sumo_step_s(value, label: str) -> float:
    """A SUMO step [s] for a multi-rate run: whole 10 ms from 0.01 to ``MAX_SUMO_STEP_S``;
    InputError naming ``label`` (the option or the file and key) otherwise."""
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
    if ok:
        n = value / 0.01
        ok = 0.01 - 1e-9 <= value <= MAX_SUMO_STEP_S + 1e-9 and abs(n - round(n)) <= 1e-6
    if not ok:
        raise InputError(
            f"{label} = {value!r} must be a multiple of 0.01 s from 0.01 to {MAX_SUMO_STEP_S:g}"
        )
    return round(value * 100.0) / 100.0


@mypyc_attr(native_class=False)  # a Python dataclass: pickled, replaced
@dataclass(frozen=True)
class RunSettings:
    """Rates, limits and sub-settings of one co-simulation run."""

    step_s: float = 0.01  # decision/control step [s]; whole milliseconds
    # SUMO's step [s], a whole multiple of ``step_s`` up to MAX_SUMO_STEP_S; None: ``step_s``
    # (one rate). Between SUMO's steps the road users are interpolated (``sim/interpolation``)
    sumo_step_s: float | None = None
    plant_dt_s: float = 0.001  # plant integration step [s]
    max_time_s: float = DEFAULT_MAX_TIME_S  # simulated time limit [s]
    settle_s: float = 2.0  # run on this long after the hand-back or a stop [s]
    # after the ego stops: run on this long [s]; None: ``settle_s`` and then for as long as
    # a road user behind it in its lane (150 m) moves towards it (``margins.follower_arriving``)
    after_stop_s: float | None = None
    ego_id: str = "ego"
    gui: bool = False
    use_traci: bool = False
    tables_dir: Path | None = None  # the tables' folder (None: offline.tables' default)
    radar: RadarSettings = field(default_factory=RadarSettings)
    eoam: EoamSettings = field(default_factory=EoamSettings)
    mu_belief: str | float = "known"  # sensing.friction: known, estimate or a number
    seed: int = 0  # seeds every random model of the run (friction estimator, radar)
    v2x: V2XSettings = field(default_factory=V2XSettings)  # used by the safe policy
    corner_radar: CornerRadarSettings = field(default_factory=CornerRadarSettings)
    radar_model: str = "ideal"  # sensing.automotive: ideal or automotive
    gui_settings: GuiSettings = field(default_factory=GuiSettings)  # with gui: pacing, view
    vehicle: VehicleParams = field(default_factory=ego_e_class_sedan)  # the ego's
    # the vehicle as chosen: a catalogue name or a vehicle file; names its tables' folder
    # under ``tables_dir`` (``sim/vehicle.py``) and is the summary's ``vehicle``
    vehicle_id: str = DEFAULT_VEHICLE
    # the ego's controller: the EOAM or a reference driver (drivers.controller.DRIVERS)
    driver: str = "eoam"

    def __post_init__(self) -> None:
        ms = self.step_s * 1000.0
        if self.step_s <= 0 or abs(ms - round(ms)) > 1e-9:
            raise ValueError(f"step_s={self.step_s} must be a positive whole number of ms")
        n = self.step_s / self.plant_dt_s
        if self.plant_dt_s <= 0 or abs(n - round(n)) > 1e-9:
            raise ValueError(f"plant_dt_s={self.plant_dt_s} must divide step_s={self.step_s}")
        if self.sumo_step_s is not None:
            k = self.sumo_step_s / self.step_s
            if not (k >= 1.0 - 1e-9 and abs(k - round(k)) <= 1e-9) or (
                self.sumo_step_s > MAX_SUMO_STEP_S + 1e-9
            ):
                raise ValueError(
                    f"sumo_step_s={self.sumo_step_s} must be a whole multiple of "
                    f"step_s={self.step_s} up to {MAX_SUMO_STEP_S:g} s"
                )
        if not 0 < self.max_time_s <= MAX_TIME_LIMIT_S:
            raise ValueError(f"max_time_s={self.max_time_s} must be in (0, {MAX_TIME_LIMIT_S:g}]")
        if self.after_stop_s is not None and not self.after_stop_s >= 0.0:
            raise ValueError(f"after_stop_s={self.after_stop_s} must be >= 0")
        if self.driver not in DRIVERS:
            raise ValueError(f"driver={self.driver!r} is not one of {', '.join(DRIVERS)}")
        if self.v2x.enabled and self.eoam.policy.name != "safe":
            raise ValueError("V2X informs the safe policy only: set policy 'safe' or V2X range 0")

    @property
    def substeps(self) -> int:
        return round(self.step_s / self.plant_dt_s)

    @property
    def sumo_step_length_s(self) -> float:
        """SUMO's step [s]: ``sumo_step_s``, or the control step."""
        return self.step_s if self.sumo_step_s is None else self.sumo_step_s

    @property
    def sumo_every(self) -> int:
        """Control steps per SUMO step (1: one rate)."""
        return round(self.sumo_step_length_s / self.step_s)
