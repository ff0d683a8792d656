"""Vehicle and physical parameters: frozen dataclasses, every value with its unit and source.

Presets are small factory functions (CommonRoad style). The paper (Lowe & Guvenc 2022) uses a
CarSim E-class sedan whose full parameter set is not public; the values below are public ones
for a vehicle of that class, each with its source in the field metadata (``unit``, ``source``).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

G_MPS2 = 9.81  # standard gravity [m/s^2]
AIR_DENSITY_KGPM3 = 1.2  # sea level, 20 C [kg/m^3]
MU_MAX = 1.2  # highest tyre-road friction accepted (lanes, runs, tables): dry asphalt [-]
#: Lateral travel of the lane change, one lane (paper sec. 4.2: y_f = 3.5 m) [m].
LANE_CHANGE_HEIGHT_M = 3.5
#: Point of no return as a fraction of the lane change's lateral travel (paper sec. 8.1) [-].
PONR_FRACTION = 0.3


def _p(default, unit: str, source: str):
    return field(default=default, metadata={"unit": unit, "source": source})


JING = "CarSim E-class sedan table, Jing et al., IEEE T-ITS 2022"
JI = "CarSim E-class sedan, Ji et al., IEEE T-VT 66(2) 2017, Table I"
W213 = "Mercedes-Benz E-Class (W213) sedan dimensions, manufacturer data sheet"
GILLESPIE = "Gillespie, Fundamentals of Vehicle Dynamics (1992), typical passenger-car value"
PAPER = "Lowe & Guvenc 2022 (the paper)"
ASSUMED = "assumed: typical value for the class, documented in README"


@dataclass(frozen=True)
class VehicleParams:
    """Single-track vehicle parameters of the ego (E-class sedan, front steer, rear drive)."""

    name: str = _p("E-class sedan", "-", PAPER + ", sec. 4.1")
    mass_kg: float = _p(1723.0, "kg", JING)
    yaw_inertia_kgm2: float = _p(4175.0, "kg m^2", JI)
    cg_to_front_m: float = _p(1.232, "m", JING)
    cg_to_rear_m: float = _p(1.468, "m", JING)
    cg_height_m: float = _p(0.54, "m", ASSUMED + " (sedan CG height 0.5-0.6 m, Gillespie)")
    track_m: float = _p(1.60, "m", W213 + " (front track 1.60 m)")
    length_m: float = _p(4.92, "m", W213)
    width_m: float = _p(1.85, "m", W213)
    front_overhang_m: float = _p(0.86, "m", W213 + " (overhang scaled to this wheelbase)")
    steering_ratio: float = _p(16.0, "-", GILLESPIE)
    max_steer_rad: float = _p(math.radians(35.0), "rad", GILLESPIE + " (road-wheel lock)")
    max_steer_rate_radps: float = _p(
        math.radians(50.0), "rad/s", ASSUMED + " (800 deg/s hand wheel / 16)"
    )
    cornering_stiffness_front_npr: float = _p(
        2 * 66900.0, "N/rad", JI + " (per tyre x 2, per axle)"
    )
    cornering_stiffness_rear_npr: float = _p(2 * 62700.0, "N/rad", JI + " (per tyre x 2, per axle)")
    slip_angle_sat_rad: float = _p(math.radians(5.0), "rad", PAPER + ", eq. 6 (alpha* = 5 deg)")
    sliding_friction_ratio: float = _p(0.8, "-", GILLESPIE + " (locked-wheel / peak friction)")
    max_drive_force_n: float = _p(6500.0, "N", ASSUMED + " (rear-drive, ~0.38 g launch)")
    max_drive_power_w: float = _p(180000.0, "W", ASSUMED + " (E-class 6-cylinder petrol)")
    max_brake_force_n: float = _p(
        22000.0, "N", ASSUMED + " (brakes able to lock all wheels on dry)"
    )
    brake_front_share: float = _p(0.65, "-", GILLESPIE + " (fixed front brake proportion)")
    rolling_resistance_coeff: float = _p(0.012, "-", GILLESPIE)
    drag_area_m2: float = _p(0.62, "m^2", ASSUMED + " (Cd 0.27 x 2.3 m^2 frontal area)")
    steer_lag_s: float = _p(0.05, "s", ASSUMED + " (electric power steering actuator)")
    drive_lag_s: float = _p(0.20, "s", ASSUMED + " (engine torque build-up)")
    brake_lag_s: float = _p(0.10, "s", ASSUMED + " (hydraulic brake build-up)")

    @property
    def wheelbase_m(self) -> float:
        return self.cg_to_front_m + self.cg_to_rear_m

    @property
    def cg_to_front_bumper_m(self) -> float:
        """Distance from the CG forward to the front bumper (SUMO places the front bumper)."""
        return self.cg_to_front_m + self.front_overhang_m

    @property
    def cg_to_rear_bumper_m(self) -> float:
        return self.length_m - self.cg_to_front_bumper_m

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            if isinstance(v, float) and not (math.isfinite(v) and v >= 0.0):
                raise ValueError(f"vehicle parameter {f.name}={v!r} must be finite and >= 0")
        if not 0.0 < self.brake_front_share < 1.0:
            raise ValueError(f"brake_front_share={self.brake_front_share} must be in (0, 1)")


@dataclass(frozen=True)
class BodyDims:
    """Footprint of another road user (for SUMO vTypes and collision geometry)."""

    name: str = _p("car", "-", ASSUMED)
    length_m: float = _p(4.7, "m", ASSUMED)
    width_m: float = _p(1.8, "m", ASSUMED)


def ego_e_class_sedan() -> VehicleParams:
    """The paper's ego: E-class sedan, front steer, rear drive, no ABS, no ESC (sec. 4.1)."""
    return VehicleParams()


def aro_d_class_minivan() -> BodyDims:
    """The paper's ARO (sec. 10.1): D-class minivan; dimensions of a Toyota Sienna (2021)."""
    return BodyDims(name="D-class minivan", length_m=5.09, width_m=1.99)


def oncoming_sedan() -> BodyDims:
    """The oncoming ARO (sec. 10.2); the paper gives no type: a D-segment sedan."""
    return BodyDims(name="D-class sedan", length_m=4.70, width_m=1.82)


def parked_car() -> BodyDims:
    """Parked cars beside the road (sec. 10.1, Figure 18): a C-segment hatchback."""
    return BodyDims(name="C-class hatchback", length_m=4.30, width_m=1.80)


def describe(params) -> dict:
    """Every field of a parameter dataclass as {name: {value, unit, source}} (for metadata)."""
    return {
        f.name: {
            "value": getattr(params, f.name),
            "unit": f.metadata.get("unit", ""),
            "source": f.metadata.get("source", ""),
        }
        for f in dataclasses.fields(params)
    }
