"""Driving a vehicle through a test: a vehicle interface, the plant behind it, and the
simulation loop that records the time series in the test's start frame.

A test drives any ``Vehicle``: ``PlantVehicle`` is our plant (``eoam_sumo.plant.Plant``); the
oracle tests drive another model through the same interface. The vehicle starts at the origin
heading along +x, so positions and yaw are in the start frame (x along the initial heading, y to
its left); velocities and accelerations are body-frame, as an on-board sensor measures them.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple, Protocol

import numpy as np

from eoam_sumo.params import VehicleParams
from eoam_sumo.plant import OUTPUT_NAMES, STATE_NAMES, Plant, initial_state
from eoam_sumo.plant.model import WHEELS
from eoam_sumo.plant.stepping import brake_force_n
from eoam_sumo.vehicle_tests.equipment import wheel_speeds

COLUMNS = (
    "time_s",
    "vx_mps",
    "vy_mps",
    "x_m",
    "y_m",
    "yaw_rad",
    "yaw_rate_radps",
    "steer_wheel_deg",
    "ax_mps2",
    "ay_mps2",
    "wheel_speed_front_mps",
    "wheel_speed_rear_mps",
    "drive_force_n",
    "brake_force_n",
    "friction_use_max",
    "friction_ellipse_max",
    "wheel_speed_min_mps",
)
"""The columns of a run's time series (``timeseries.csv``), in order."""

STEP_S = 0.01
"""Recording and driver step [s]: the co-simulation's step (the plant sub-steps 1 ms)."""


class Sample(NamedTuple):
    """The vehicle's state after a step; the steering is the road-wheel angle."""

    vx_mps: float
    vy_mps: float
    x_m: float
    y_m: float
    yaw_rad: float
    yaw_rate_radps: float
    steer_road_rad: float
    ax_mps2: float
    ay_mps2: float
    wheel_speed_front_mps: float
    wheel_speed_rear_mps: float
    drive_force_n: float
    brake_force_n: float
    friction_use_max: float = math.nan  # the largest tyre |F| / (mu Fz) (NaN: not modelled)
    friction_ellipse_max: float = math.nan  # the largest tyre sqrt((Fx/Dx)^2 + (Fy/Dy)^2)
    wheel_speed_min_mps: float = math.nan  # the slowest of the four wheels (omega r_w)


class Controls(NamedTuple):
    """What the test's driver commands: the plant's inputs (``INPUT_NAMES``)."""

    steer_cmd_rad: float
    drive_force_cmd_n: float
    brake_force_cmd_n: float


class Vehicle(Protocol):
    """What a test drives: started straight at a speed, then advanced ``STEP_S`` at a time."""

    params: VehicleParams

    def start(self, speed_mps: float) -> Sample: ...

    def advance(self, controls: Controls, mu: float) -> Sample: ...


Driver = Callable[[float, Sample], Controls]
"""The test's driver: (time since the start [s], latest sample) -> controls."""
Stop = Callable[[float, Sample], bool]


_STATE = {name: i for i, name in enumerate(STATE_NAMES)}
_OUTPUT = {name: i for i, name in enumerate(OUTPUT_NAMES)}
_USE = tuple(_OUTPUT[f"friction_use_{w}"] for w in WHEELS)
_ELLIPSE = tuple(_OUTPUT[f"friction_ellipse_{w}"] for w in WHEELS)
_WHEEL_SPEEDS = tuple(_OUTPUT[f"wheel_speed_{w}_mps"] for w in WHEELS)


class PlantVehicle:
    """Our plant (compiled, 1 ms sub-steps) behind the ``Vehicle`` interface."""

    def __init__(self, params: VehicleParams):
        self.params = params
        self._plant = Plant(params, dt_s=0.001, substeps=round(STEP_S / 0.001))
        self._x: list[float] = []

    def start(self, speed_mps: float) -> Sample:
        self._x = [float(v) for v in initial_state(0.0, 0.0, 0.0, speed_mps, params=self.params)]
        return rolling_start(speed_mps)

    def advance(self, controls: Controls, mu: float) -> Sample:
        self._x, outputs = self._plant.advance(self._x, list(controls), mu)
        return self._sample(self._x, outputs)

    def _sample(self, x: list[float], outputs: list[float]) -> Sample:
        vx_mps = x[_STATE["vx_mps"]]
        front_mps, rear_mps = wheel_speeds(outputs)
        return Sample(
            vx_mps=vx_mps,
            vy_mps=x[_STATE["vy_mps"]],
            x_m=x[_STATE["x_m"]],
            y_m=x[_STATE["y_m"]],
            yaw_rad=x[_STATE["yaw_rad"]],
            yaw_rate_radps=x[_STATE["yaw_rate_radps"]],
            steer_road_rad=x[_STATE["steer_rad"]],
            ax_mps2=outputs[_OUTPUT["ax_mps2"]],
            ay_mps2=outputs[_OUTPUT["ay_mps2"]],
            wheel_speed_front_mps=front_mps,
            wheel_speed_rear_mps=rear_mps,
            drive_force_n=x[_STATE["drive_force_n"]],
            brake_force_n=brake_force_n(x, self.params),
            friction_use_max=max(outputs[i] for i in _USE),
            friction_ellipse_max=max(outputs[i] for i in _ELLIPSE),
            wheel_speed_min_mps=min(outputs[i] for i in _WHEEL_SPEEDS),
        )


def rolling_start(speed_mps: float) -> Sample:
    """The sample of a vehicle at the origin rolling straight along +x at ``speed_mps``."""
    return Sample(
        speed_mps, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, speed_mps, speed_mps, 0.0, 0.0,
        wheel_speed_min_mps=speed_mps,
    )  # fmt: skip


@dataclass(frozen=True)
class Run:
    """One run's time series, ``COLUMNS`` as arrays, and its label (``amp_2.0A``, ``run``)."""

    label: str
    columns: dict[str, np.ndarray]

    def __getitem__(self, name: str) -> np.ndarray:
        return self.columns[name]


def simulate(
    vehicle: Vehicle,
    speed_mps: float,
    driver: Driver,
    duration_s: float,
    mu: float,
    *,
    label: str = "run",
    stop: Stop | None = None,
) -> Run:
    """Drive ``vehicle`` from ``speed_mps`` straight ahead for ``duration_s`` (or until
    ``stop``), ``driver`` commanding every ``STEP_S``; the run's time series."""
    ratio = vehicle.params.steering_ratio
    sample = vehicle.start(speed_mps)
    rows = [_row(0.0, sample, ratio)]
    steps = round(duration_s / STEP_S)
    for k in range(steps):
        t_s = k * STEP_S
        sample = vehicle.advance(driver(t_s, sample), mu)
        rows.append(_row(t_s + STEP_S, sample, ratio))
        if stop is not None and stop(t_s + STEP_S, sample):
            break
    table = np.array(rows, dtype=float)
    return Run(label, {name: table[:, i] for i, name in enumerate(COLUMNS)})


def _row(t_s: float, s: Sample, steering_ratio: float) -> tuple[float, ...]:
    steer_wheel_deg = math.degrees(s.steer_road_rad) * steering_ratio
    return (
        t_s, s.vx_mps, s.vy_mps, s.x_m, s.y_m, s.yaw_rad, s.yaw_rate_radps, steer_wheel_deg,
        s.ax_mps2, s.ay_mps2, s.wheel_speed_front_mps, s.wheel_speed_rear_mps,
        s.drive_force_n, s.brake_force_n, s.friction_use_max, s.friction_ellipse_max,
        s.wheel_speed_min_mps,
    )  # fmt: skip
