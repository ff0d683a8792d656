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
#: A lane wider than this holds two cars side by side (Vector's NCAP road is one 28 m lane each
#: way): a lane change from or into it swerves by the tables' ``LANE_CHANGE_HEIGHT_M`` (or as
#: far as the obstacle needs), not to the far lane's centre (ours) [m].
WIDE_LANE_M = 6.0
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
NHTSA_INERTIA = (
    "Heydinger et al., Measured vehicle inertial parameters - NHTSA's data through November "
    "1998, SAE 1999-01-1336 (passenger cars: dynamic index k^2/(a b) close to 1)"
)
R13H = (
    "UN R13-H Annex 5 para. 3.1.1 (as Directive 71/320/EEC Annex II Appendix 3.1.1): "
    "front axle's adhesion utilisation above the rear's for braking rates 0.15-0.8"
)
PAC2002 = (
    "MSC Adams PAC2002 sample tyre 235/60R16 (FNOMIN 4850 N, R0 0.344 m), the set "
    "CommonRoad vehicle models ship (Althoff & Wuersching 2020, Tab. 7)"
)
CHASSIS = "docs/chassis.md"
DRIVETRAINS = ("fwd", "rwd", "awd", "eawd")


@dataclass(frozen=True)
class VehicleParams:
    """Single-track vehicle parameters of the ego (E-class sedan, front steer, rear drive)."""

    name: str = _p("E-class sedan", "-", PAPER + ", sec. 4.1")
    mass_kg: float = _p(1723.0, "kg", JING)
    yaw_inertia_kgm2: float = _p(
        4175.0, "kg m^2", JI + " (k^2/(a b) = 1.34; vehicles/sedan-r13h.toml: 3116, 1.0)"
    )
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
    brake_front_share: float = _p(
        0.65,
        "-",
        GILLESPIE + " (fixed front brake proportion; locks the rear first on dry road, "
        "vehicles/sedan-r13h.toml: 0.73)",
    )
    rolling_resistance_coeff: float = _p(0.012, "-", GILLESPIE)
    drag_area_m2: float = _p(0.62, "m^2", ASSUMED + " (Cd 0.27 x 2.3 m^2 frontal area)")
    steer_lag_s: float = _p(0.05, "s", ASSUMED + " (electric power steering actuator)")
    drive_lag_s: float = _p(0.20, "s", ASSUMED + " (engine torque build-up)")
    brake_lag_s: float = _p(0.10, "s", ASSUMED + " (hydraulic brake build-up)")
    # --- the chassis (plant only; the offline design does not use these, DESIGN_FIELDS) ---
    wheel_radius_m: float = _p(0.334, "m", PAC2002 + ": R0 less 3 % deflection")
    wheel_inertia_kgm2: float = _p(1.7, "kg m^2", "CommonRoad vehicle 2 (BMW 320i), I_y_w")
    tyre_nominal_load_n: float = _p(
        4850.0, "N", PAC2002 + " (FNOMIN; the plant scales the set to it, MF 5.2 LFZO)"
    )
    relaxation_length_long_m: float = _p(
        0.25, "m", PAC2002 + ": K_x/C_x at FNOMIN (Pacejka 2012 sec. 7.2)"
    )
    relaxation_length_lat_m: float = _p(
        0.60, "m", PAC2002 + ": PTY1 sin(2 atan(1/PTY2)) R0 (Pacejka 2012 sec. 7.2)"
    )
    front_steer_compliance: float = _p(
        1.0,
        "-",
        PAPER + " (its car's front axle as stiff as its tyres; vehicles/sedan-r13h.toml: 0.75, "
        "Gillespie ch. 6 steering compliance, understeer gradient 1.7 deg/g)",
    )
    roll_stiffness_front_share: float = _p(
        0.60, "-", GILLESPIE + " (front-biased roll stiffness of a sedan)"
    )
    max_brake_pressure_bar: float = _p(150.0, "bar", ASSUMED + " (ABS modulator range)")
    brake_build_rate_barps: float = _p(1500.0, "bar/s", ASSUMED + " (booster + ABS pump)")
    brake_dump_rate_barps: float = _p(3000.0, "bar/s", ASSUMED + " (ABS outlet valve)")
    abs_fitted: bool = _p(False, "-", PAPER + ", sec. 4.1 (no ABS)")
    esc_fitted: bool = _p(False, "-", PAPER + ", sec. 4.1 (no ESC)")
    drivetrain: str = _p("rwd", "-", PAPER + ", sec. 4.1 (rear drive); fwd|rwd|awd|eawd")
    awd_front_share: float = _p(0.40, "-", ASSUMED + " (fixed AWD torque split to the front)")
    eawd_gain_per_slip: float = _p(
        10.0, "-", CHASSIS + ": front share moved per unit slip difference (eAWD)"
    )
    esc_yaw_gain: float = _p(15.0, "1/s", CHASSIS + ": moment / (Iz yaw-rate error), tuned SWD")
    esc_yaw_deadband_radps: float = _p(0.03, "rad/s", CHASSIS + " (tuned on SWD)")
    esc_sideslip_threshold_rad: float = _p(
        math.radians(4.0), "rad", CHASSIS + " (sideslip beyond which ESC acts)"
    )
    esc_sideslip_gain_nmprad: float = _p(60000.0, "N m/rad", CHASSIS + " (tuned on SWD)")
    esc_lag_s: float = _p(0.08, "s", ASSUMED + " (ESC hydraulic build-up)")

    @property
    def wheelbase_m(self) -> float:
        return self.cg_to_front_m + self.cg_to_rear_m

    @property
    def front_axle_stiffness_npr(self) -> float:
        """The front axle's effective cornering stiffness in the plant: its tyres' times the
        steering compliance (Gillespie ch. 6)."""
        return self.front_steer_compliance * self.cornering_stiffness_front_npr

    @property
    def understeer_gradient_rad_per_mps2(self) -> float:
        """The linear single-track understeer gradient K_us = m (b / C_f - a / C_r) / L, C_f
        the front axle's effective stiffness (``front_axle_stiffness_npr``; Gillespie ch. 6)."""
        return (
            self.mass_kg
            * (
                self.cg_to_rear_m / self.front_axle_stiffness_npr
                - self.cg_to_front_m / self.cornering_stiffness_rear_npr
            )
            / self.wheelbase_m
        )

    @property
    def cg_to_front_bumper_m(self) -> float:
        """Distance from the CG forward to the front bumper (SUMO places the front bumper)."""
        return self.cg_to_front_m + self.front_overhang_m

    @property
    def cg_to_rear_bumper_m(self) -> float:
        return self.length_m - self.cg_to_front_bumper_m

    def __post_init__(self) -> None:
        check_vehicle(self)


#: Each numeric ``VehicleParams`` field's physical range ``(low, high)``, closed, in the
#: field's unit: wide enough for any road vehicle from a light quadricycle (about 350 kg) to
#: a 60 t road train, narrow enough that the plant's fixed 1 ms step stays stable and no
#: division by zero is possible. The reason of each range: docs/vehicles.md.
VEHICLE_RANGES: dict[str, tuple[float, float]] = {
    "mass_kg": (200.0, 60000.0),
    "yaw_inertia_kgm2": (20.0, 2.0e6),
    "cg_to_front_m": (0.2, 6.0),
    "cg_to_rear_m": (0.2, 6.0),
    "cg_height_m": (0.2, 3.0),
    "track_m": (0.8, 2.6),
    "length_m": (2.0, 25.25),
    "width_m": (1.0, 2.6),
    "front_overhang_m": (0.0, 3.0),
    "steering_ratio": (5.0, 40.0),
    "max_steer_rad": (0.1, 1.2),
    "max_steer_rate_radps": (0.05, 5.0),
    "cornering_stiffness_front_npr": (1.0e4, 3.0e6),
    "cornering_stiffness_rear_npr": (1.0e4, 3.0e6),
    "slip_angle_sat_rad": (0.02, 0.35),
    "sliding_friction_ratio": (0.3, 1.0),
    "max_drive_force_n": (100.0, 6.0e5),
    "max_drive_power_w": (1.0e3, 2.0e6),
    "max_brake_force_n": (500.0, 1.0e6),
    "brake_front_share": (0.05, 0.95),
    "rolling_resistance_coeff": (0.0, 0.05),
    "drag_area_m2": (0.0, 15.0),
    "steer_lag_s": (0.005, 2.0),
    "drive_lag_s": (0.005, 2.0),
    "brake_lag_s": (0.005, 2.0),
    "wheel_radius_m": (0.15, 0.75),
    "wheel_inertia_kgm2": (0.1, 50.0),
    "tyre_nominal_load_n": (500.0, 60000.0),
    "relaxation_length_long_m": (0.05, 2.0),
    "relaxation_length_lat_m": (0.05, 2.0),
    "front_steer_compliance": (0.3, 1.0),
    "roll_stiffness_front_share": (0.1, 0.9),
    "max_brake_pressure_bar": (5.0, 300.0),
    "brake_build_rate_barps": (10.0, 20000.0),
    "brake_dump_rate_barps": (10.0, 50000.0),
    "awd_front_share": (0.0, 1.0),
    "eawd_gain_per_slip": (0.0, 100.0),
    "esc_yaw_gain": (0.0, 100.0),
    "esc_yaw_deadband_radps": (0.0, 0.5),
    "esc_sideslip_threshold_rad": (0.0, 0.35),
    "esc_sideslip_gain_nmprad": (0.0, 1.0e7),
    "esc_lag_s": (0.005, 2.0),
}
#: FNOMIN of the plant's one tyre set, the PAC2002 235/60R16 (``plant.magic_formula``) [N];
#: the plant scales it to each vehicle's ``tyre_nominal_load_n`` (MF 5.2's LFZO).
PLANT_TYRE_FNOMIN_N = 4850.0
#: The plant tyre's longitudinal peak friction per unit load increment, PDX2 / PDX1 of the
#: PAC2002 235/60R16 (``plant.magic_formula``): mu_x(Fz) = mu (1 + this (Fz - FNOMIN) / FNOMIN)
#: (Pacejka 2012 eq. 4.E13 with LMUX = mu / PDX1) [-].
PLANT_TYRE_PEAK_LOAD_SENSITIVITY = -0.16395 / 1.1739
#: Static load per tyre the plant's tyre describes, as multiples of its FNOMIN: its
#: load-variation terms (PDX2, PDY2) take its peak friction to zero near 6 x FNOMIN, and a
#: limit manoeuvre's load transfer can double a tyre's load (docs/vehicles.md, the tyre).
TYRE_LOAD_RANGE = (0.1, 2.0)
#: The dynamic index ``k^2 / (a b)`` (``k^2 = Iz / m``) a vehicle may have: measured cars lie
#: within 0.7-1.4 (Heydinger et al., SAE 1999-01-1336); a body's mass cannot all sit at or
#: beyond its axles' reach many times over, nor at one point.
DYNAMIC_INDEX_RANGE = (0.3, 3.0)


class VehicleValueError(ValueError):
    """A vehicle value out of its range: ``field`` and what is wrong with it (``detail``,
    starting with its value), so that a file's loader can name the key."""

    def __init__(self, field: str, detail: str):
        super().__init__(f"vehicle parameter {field} {detail}")
        self.field = field
        self.detail = detail


def _in_range(name: str, value: float, unit: str, low: float, high: float) -> None:
    if not low <= value <= high:  # False for NaN too
        raise VehicleValueError(
            name, f"= {value!r} {unit} is outside its physical range [{low:g}, {high:g}] {unit}"
        )


def check_vehicle(p: VehicleParams) -> None:
    """``ValueError`` naming the field, its value and unit unless every value has its type and
    lies in its physical range (``VEHICLE_RANGES``) and the geometry is consistent."""
    units = {f.name: f.metadata.get("unit", "") for f in dataclasses.fields(p)}
    for name, (low, high) in VEHICLE_RANGES.items():
        value = getattr(p, name)
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise VehicleValueError(name, f"= {value!r} must be a number")
        _in_range(name, float(value), units[name], low, high)
    if not isinstance(p.name, str) or not p.name.strip():
        raise VehicleValueError("name", f"= {p.name!r} must be a non-empty string")
    if p.drivetrain not in DRIVETRAINS:
        raise VehicleValueError("drivetrain", f"= {p.drivetrain!r} is not one of {DRIVETRAINS}")
    for name in ("abs_fitted", "esc_fitted"):
        if not isinstance(getattr(p, name), bool):
            raise VehicleValueError(name, f"= {getattr(p, name)!r} must be a bool")
    _check_relations(p)


def _check_relations(p: VehicleParams) -> None:
    """The axles within the body, the track within the width, a physical dynamic index, the
    static tyre loads within what the plant's tyre describes."""
    axles_m = p.front_overhang_m + p.wheelbase_m
    if axles_m > p.length_m:
        raise VehicleValueError(
            "length_m",
            f"= {p.length_m!r} m is shorter than front_overhang_m + cg_to_front_m + "
            f"cg_to_rear_m = {axles_m:.3f} m (the rear axle outside the body)",
        )
    if p.track_m > p.width_m:
        raise VehicleValueError("track_m", f"= {p.track_m!r} m exceeds width_m = {p.width_m!r} m")
    index = p.yaw_inertia_kgm2 / p.mass_kg / (p.cg_to_front_m * p.cg_to_rear_m)
    low, high = DYNAMIC_INDEX_RANGE
    if not low <= index <= high:
        raise VehicleValueError(
            "yaw_inertia_kgm2",
            f"= {p.yaw_inertia_kgm2!r} kg m^2 gives a dynamic index Iz / (m a b) = {index:.3g} "
            f"outside [{low:g}, {high:g}] for this mass and these axle distances",
        )
    weight_n = p.mass_kg * G_MPS2
    for axle, share in (("front", p.cg_to_rear_m), ("rear", p.cg_to_front_m)):
        load = 0.5 * weight_n * share / p.wheelbase_m / p.tyre_nominal_load_n
        if not TYRE_LOAD_RANGE[0] <= load <= TYRE_LOAD_RANGE[1]:
            raise VehicleValueError(
                "mass_kg",
                f"= {p.mass_kg!r} kg puts {load:.2f} x FNOMIN on each {axle} tyre, outside "
                f"[{TYRE_LOAD_RANGE[0]:g}, {TYRE_LOAD_RANGE[1]:g}] x "
                f"tyre_nominal_load_n = {p.tyre_nominal_load_n:g} N, what the plant's "
                "passenger-car tyre (PAC2002 235/60R16, scaled to that nominal load) describes",
            )


@dataclass(frozen=True)
class BodyDims:
    """Footprint of another road user (for SUMO vTypes and collision geometry)."""

    name: str = _p("car", "-", ASSUMED)
    length_m: float = _p(4.7, "m", ASSUMED)
    width_m: float = _p(1.8, "m", ASSUMED)


WHEELS = 4  # the plant's two axles of two wheels, each of ``wheel_inertia_kgm2``


def equivalent_mass_kg(params: VehicleParams) -> float:
    """``m + 4 J_w / r_w^2`` [kg]: the mass a longitudinal force at the road accelerates with
    the wheels rolling (Gillespie 1992, eq. 2-5, the rotating-inertia mass factor)."""
    return params.mass_kg + WHEELS * params.wheel_inertia_kgm2 / params.wheel_radius_m**2


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
