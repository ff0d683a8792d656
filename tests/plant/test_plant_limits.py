"""Friction bounds for arbitrary inputs (hypothesis) and a locked front axle that barely steers.

What is measured: the axle forces against the friction of their loads, the body's
acceleration produced by the tyres, ``(ax + F_drag / m, ay)`` from the outputs, and,
independently of the outputs, the change of the ground-frame velocity over each 10 ms step,
which may exceed ``mu g`` only by the tyres' load sensitivity (``MU_LOAD``) and the drag.
"""

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from eoam_sumo.params import AIR_DENSITY_KGPM3, G_MPS2
from eoam_sumo.plant import OUTPUT_NAMES, STATE_NAMES, initial_state
from eoam_sumo.plant.magic_formula import PAC2002_235_60R16

S = {name: i for i, name in enumerate(STATE_NAMES)}
TYRE = PAC2002_235_60R16
MU_LOAD = max(1.0 - TYRE.pdx2 / TYRE.pdx1, 1.0 - TYRE.pdy2 / TYRE.pdy1)
"""The most a tyre's friction can exceed the road's mu (at zero load, dfz = -1: PDX2, PDY2 < 0;
the larger of the longitudinal 1.14 and the lateral 1.17), as the MF's load sensitivity
gives."""
Y = {name: i for i, name in enumerate(OUTPUT_NAMES)}

segment = st.tuples(
    st.floats(-0.8, 0.8),  # steering command [rad], beyond the 35 deg lock on purpose
    st.floats(0.0, 9000.0),  # drive command [N], beyond the maximum on purpose
    st.floats(0.0, 25000.0),  # brake command [N]
    st.floats(0.1, 1.2),  # surface friction
    st.integers(1, 40),  # steps the segment is held
)


def world_velocity(x):
    c, s = math.cos(x[S["yaw_rad"]]), math.sin(x[S["yaw_rad"]])
    vx, vy = x[S["vx_mps"]], x[S["vy_mps"]]
    return np.array([vx * c - vy * s, vx * s + vy * c])


@settings(max_examples=200, deadline=None, derandomize=True, database=None)
@given(
    speed=st.floats(0.0, 46.0),
    yaw=st.floats(-math.pi, math.pi),
    segments=st.lists(segment, min_size=1, max_size=6),
)
def test_tyres_never_exceed_friction_and_state_stays_finite(plant, params, speed, yaw, segments):
    m, g = params.mass_kg, G_MPS2
    k_drag = 0.5 * AIR_DENSITY_KGPM3 * params.drag_area_m2
    x = initial_state(0.0, 0.0, yaw, speed)
    for steer, drive, brake, mu, hold in segments:
        u = np.array([steer, drive, brake])
        for _ in range(hold):
            x_next, y = plant.step(x, u, mu)
            assert np.all(np.isfinite(x_next)) and np.all(np.isfinite(y))
            assert abs(x_next[S["steer_rad"]]) <= params.max_steer_rad * (1 + 1e-12)
            # the loads add up to the weight, a lifted wheel's load passed on, not made up
            assert abs(y[Y["fz_front_n"]] + y[Y["fz_rear_n"]] - m * g) <= 1e-9 * m * g
            # a wheel turns backwards only as the ground under it moves backwards
            side_mps = 0.5 * params.track_m * abs(x_next[S["yaw_rate_radps"]])
            ground_mps = min(x_next[S["vx_mps"]] - side_mps, 0.0)
            wheel = min(y[Y["wheel_speed_front_mps"]], y[Y["wheel_speed_rear_mps"]])
            assert wheel >= ground_mps - 1e-9
            for axle in ("front", "rear"):
                force = math.hypot(y[Y[f"fx_{axle}_n"]], y[Y[f"fy_{axle}_n"]])
                assert force <= MU_LOAD * mu * y[Y[f"fz_{axle}_n"]] * (1 + 1e-9) + 1e-2
            tyre_accel = math.hypot(y[Y["ax_mps2"]] + y[Y["drag_force_n"]] / m, y[Y["ay_mps2"]])
            assert tyre_accel <= MU_LOAD * mu * g * (1 + 1e-9) + 1e-5
            fastest = max(x[S["vx_mps"]], x_next[S["vx_mps"]]) + 0.1
            dv = np.linalg.norm(world_velocity(x_next) - world_velocity(x)) / plant.step_s
            assert dv <= 1.05 * MU_LOAD * mu * g + k_drag * fastest**2 / m
            x = x_next


@settings(max_examples=100, deadline=None, derandomize=True, database=None)
@given(
    speed=st.floats(0.0, 46.0),
    segments=st.lists(
        st.tuples(st.floats(0.0, 9000.0), st.floats(0.0, 25000.0), st.floats(0.1, 1.2)),
        min_size=1,
        max_size=6,
    ),
)
def test_straight_line_braking_and_driving_never_reverse(plant, speed, segments):
    # No clamp on vx: the wheels' brake and rolling resistance stop at zero spin, and the
    # relaxed slip settles without ringing (a stop leaves a sub-mm/s rebound at most).
    x = initial_state(0.0, 0.0, 0.0, speed)
    for drive, brake, mu in segments:
        for _ in range(60):
            x, _ = plant.step(x, np.array([0.0, drive, brake]), mu)
            assert x[S["vx_mps"]] >= -0.01
            assert x[S["vy_mps"]] == 0.0 and x[S["yaw_rate_radps"]] == 0.0 and x[S["y_m"]] == 0.0
            assert x[S["x_m"]] >= -0.001


def run_braked_turn(plant, mu, brake_n, steer_rad, steps=100):
    """80 km/h straight, brake actuator at ``brake_n``, then steer; returns the history."""
    x = initial_state(0.0, 0.0, 0.0, 80.0 / 3.6, brake_force_n=brake_n)
    u = np.array([steer_rad, 0.0, brake_n])
    history = []
    for _ in range(steps):
        x, y = plant.step(x, u, mu)
        history.append((x, y))
    return history


def test_locked_front_axle_barely_steers(plant):
    steer = math.radians(5.0)
    # 1.8 kN on ice: the front brake (73 %) exceeds mu Fz_f, the rear one stays below mu Fz_r.
    locked = run_braked_turn(plant, 0.1, 1800.0, steer)
    for _, y in locked[60:]:  # the wheels spin down in 0.4 s (a small excess torque)
        assert y[Y["front_locked"]] == 1.0 and y[Y["rear_locked"]] == 0.0
    assert locked[-1][0][S["steer_rad"]] > 0.9 * steer  # the wheels ARE steered
    # The same steering with the brakes off turns the car; locked, a sliding tyre's lateral
    # force (MF combined slip at kappa = -1) is a small fraction of it.
    rolling = run_braked_turn(plant, 0.1, 0.0, steer)
    assert rolling[-1][0][S["yaw_rate_radps"]] > 0.02
    assert rolling[-1][0][S["y_m"]] > 0.2
    assert abs(locked[-1][0][S["y_m"]]) < 0.3 * rolling[-1][0][S["y_m"]]


def test_fully_locked_car_slides_nearly_straight_on_ice(plant, params):
    history = run_braked_turn(plant, 0.1, params.max_brake_force_n, math.radians(10.0))
    rolling = run_braked_turn(plant, 0.1, 0.0, math.radians(10.0))
    for _, y in history[30:]:
        assert y[Y["front_locked"]] == 1.0 and y[Y["rear_locked"]] == 1.0
    assert abs(history[-1][0][S["y_m"]]) < 0.3 * abs(rolling[-1][0][S["y_m"]])
    decel = -history[-1][1][Y["ax_mps2"]] - history[-1][1][Y["drag_force_n"]] / params.mass_kg
    # the MF's locked-wheel force: about 0.7 of the peak for this tyre set (less drag)
    assert 0.5 * 0.1 * G_MPS2 < decel < 0.85 * 0.1 * G_MPS2


def test_a_spin_past_ninety_degrees_stays_within_friction(plant, params):
    # Hard steer and brake at 100 km/h on a road that turns icy: the car spins, its body-frame
    # vx turns negative, and the tyres still decelerate it within the friction limit.
    k_drag = 0.5 * AIR_DENSITY_KGPM3 * params.drag_area_m2
    x = initial_state(0.0, 0.0, 0.0, 100.0 / 3.6)
    speeds, min_vx = [], math.inf
    for k in range(600):
        t = k * 0.01
        steer = math.radians(4.0) * math.sin(2 * math.pi * t / 3.0) if t < 3.0 else 0.0
        u = np.array([steer, 2500.0 if t >= 3.0 else 0.0, 9000.0 if 1.0 <= t < 2.6 else 0.0])
        mu = 0.8 if t < 2.0 else 0.3
        x_next, y = plant.step(x, u, mu)
        assert np.all(np.isfinite(x_next)) and np.all(np.isfinite(y))
        fastest = max(np.linalg.norm(world_velocity(x)), np.linalg.norm(world_velocity(x_next)))
        dv = np.linalg.norm(world_velocity(x_next) - world_velocity(x)) / plant.step_s
        assert dv <= 1.05 * MU_LOAD * mu * G_MPS2 + k_drag * fastest**2 / params.mass_kg
        speeds.append(np.linalg.norm(world_velocity(x_next)))
        min_vx = min(min_vx, x_next[S["vx_mps"]])
        x = x_next
    assert min_vx < -5.0, "the manoeuvre is meant to spin the car"
    assert speeds[-1] < 0.7 * speeds[0]
