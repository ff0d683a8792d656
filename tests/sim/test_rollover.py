"""Rollover as a loss of control (no SUMO): the limits against the plant's own load transfer,
the watch on a run's steps, and the verdict it gives."""

from __future__ import annotations

import math
from dataclasses import replace
from types import SimpleNamespace

import pytest
from hypothesis import given
from hypothesis import strategies as st

from eoam_sumo.params import G_MPS2, ego_e_class_sedan
from eoam_sumo.plant.model import AX_LOAD, AY_LOAD, STATE_NAMES, tyre_loads_n
from eoam_sumo.plant.ops import FLOAT_OPS
from eoam_sumo.sim.facts import RunFacts
from eoam_sumo.sim.observers import RolloverWatch
from eoam_sumo.sim.vehicle import TYRES, rollover_limits
from eoam_sumo.sim.verdict import outcome_of

SEDAN = ego_e_class_sedan()
TALL = replace(SEDAN, name="tall", cg_height_m=1.6)


def _state(ax: float, ay: float) -> list[float]:
    x = [0.0] * len(STATE_NAMES)
    x[AX_LOAD], x[AY_LOAD] = ax, ay
    return x


@given(st.floats(-6.0, 6.0), st.floats(-6.0, 6.0))
def test_the_limits_give_the_plants_tyre_loads(ax, ay):
    limits = rollover_limits(SEDAN)
    plant = tyre_loads_n(_state(ax, ay), SEDAN, FLOAT_OPS)
    for i in range(4):
        ours = limits.static_n[i] + limits.per_ax[i] * ax + limits.per_ay[i] * ay
        assert ours == pytest.approx(float(plant[i]), abs=1e-6)


def test_static_stability_limit_is_g_track_over_twice_the_cg_height():
    # Gillespie ch. 9: a rigid car tips at ay / g = track / (2 h)
    assert rollover_limits(SEDAN).ssf_ay_mps2 == pytest.approx(G_MPS2 * 1.60 / (2 * 0.54))
    assert rollover_limits(TALL).ssf_ay_mps2 == pytest.approx(G_MPS2 * 1.60 / 3.2)


def _watch(params):
    return RolloverWatch(*rollover_limits(params), AX_LOAD, AY_LOAD, TYRES)


def _step(watch: RolloverWatch, ax: float, ay: float, t: float = 1.0) -> None:
    watch.after_step(SimpleNamespace(x=_state(ax, ay), ay=ay, t=t))


def test_one_inner_wheel_lifting_is_reported_and_both_are_a_rollover():
    watch = _watch(TALL)
    watch.start(None)
    # the inner front wheel lifts when its share (0.6) of m ay h / track is half the front
    # axle's load, m g b / (2 L): at ay = g b track / (1.2 L h), 4.44 m/s2; the inner rear
    # when its share (0.4) is half the rear's, m g a / (2 L): at g a track / (0.8 L h)
    h, t, wb = 1.6, TALL.track_m, TALL.wheelbase_m
    front = G_MPS2 * TALL.cg_to_rear_m * t / (1.2 * wb * h)
    rear = G_MPS2 * TALL.cg_to_front_m * t / (0.8 * wb * h)
    assert front < rear
    _step(watch, 0.0, 0.99 * front, t=1.0)
    assert watch.lift_time_s is None and watch.min_load_n > 0.0
    _step(watch, 0.0, 1.01 * front, t=1.01)
    assert watch.time_s is None  # one wheel up: reported, no loss of control
    assert watch.lift_time_s == 1.01 and watch.lift_tyre == "front left"
    assert watch.lift_ay_mps2 == pytest.approx(1.01 * front)
    assert watch.min_load_n == 0.0
    _step(watch, 0.0, 1.01 * rear, t=1.5)
    assert watch.time_s == 1.5 and watch.cause == "both inner left wheels lifted"
    assert watch.lift_time_s == 1.01  # the first lift is kept


def test_braking_that_unloads_the_rear_without_roll_is_no_rollover():
    watch = _watch(TALL)
    watch.start(None)
    _step(watch, -9.0, 0.0)  # pitch: both rear loads at zero, nothing rolls
    assert watch.time_s is None and watch.min_load_n == 0.0


def test_the_static_stability_limit_alone_is_a_rollover():
    params = replace(SEDAN, roll_stiffness_front_share=0.5, cg_height_m=0.9)
    watch = _watch(params)
    watch.start(None)
    limit = rollover_limits(params).ssf_ay_mps2
    watch.after_step(SimpleNamespace(x=_state(0.0, 0.0), ay=-1.01 * limit, t=2.0))
    assert watch.time_s == 2.0 and "static stability limit" in watch.cause


def test_the_sedan_keeps_its_wheels_down_at_the_friction_limit():
    watch = _watch(SEDAN)
    watch.start(None)
    for ay in (-9.81, 9.81):
        _step(watch, 0.0, ay)
    _step(watch, -6.9, 6.9)  # braking and turning at 1 g
    assert watch.time_s is None and watch.min_load_n > 1000.0


def _facts(**kw) -> RunFacts:
    return RunFacts(lane_width_m=3.5, left_lane=True, ego_mass_kg=1723.0, **kw)


def test_a_rollover_is_orange_without_contact_and_says_so():
    facts = _facts(
        modes_visited=(0, 1, 2),
        rollover_time_s=3.92,
        rollover_cause="both inner left wheels lifted",
        end_cause="rollover",
        manoeuvre_running=True,
        max_abs_offset_m=0.2,
        max_offset_m=0.2,
    )
    out = outcome_of(facts)
    assert out.colour == "orange" and out.collision_with == "none"
    assert "rollover: both inner left wheels lifted at t=3.92 s" in out.reason
    assert outcome_of(replace(facts, rollover_time_s=None)).colour != "orange"
    assert math.isinf(_facts(modes_visited=(0,)).min_tyre_load_n)
