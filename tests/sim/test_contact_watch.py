"""The contact check and the obstacle's gap watch road users of any length (no SUMO)."""

from __future__ import annotations

import math

import pytest

from eoam_sumo.plant import initial_state
from eoam_sumo.sim.cosim import CoSimulation
from eoam_sumo.sim.roadframe import RoadFrame
from eoam_sumo.sim.settings import RunSettings
from eoam_sumo.world.bodies import Body


def _checked(front_gap_m: float, length_m: float) -> CoSimulation:
    """A standing ego at the origin heading +x and a standing road user ``length_m`` long
    whose rear is ``front_gap_m`` ahead of the ego's front bumper, in its lane; the contact
    check run once."""
    sim = object.__new__(CoSimulation)
    sim.settings = settings = RunSettings()
    sim.params = p = settings.vehicle
    sim.road = RoadFrame([(-200.0, 0.0), (800.0, 0.0)])
    sim.lane_width_m = 3.6
    sim._set_up_geometry()
    sim.x = sim.x_prev = initial_state(0.0, 0.0, 0.0, 0.0, params=p).tolist()
    sim._cy, sim._sy = 1.0, 0.0
    sim._reach_pad_m, sim.t = 0.05, 10.0
    centre_x_m = p.cg_to_front_bumper_m + front_gap_m + 0.5 * length_m
    other = Body("obstacle", "trailer", centre_x_m, 0.0, 0.0, 0.0, length_m, 2.5)
    sim.bodies = sim.bodies_before = [other]
    sim.first_contact, sim.min_gap_aro_m = None, math.inf
    sim._gaps, sim._gaps_pose, sim._met_ahead = {}, None, {}
    sim.check_contact()
    return sim


@pytest.mark.parametrize("length_m", [4.5, 16.5, 60.0])
def test_the_gap_to_a_long_obstacle_is_measured(length_m):
    """The gap to an obstacle 10 m ahead is measured whatever its length (a 60 m trailer's
    centre is 41 m from the ego's: it was skipped, the gap left unmeasured)."""
    sim = _checked(10.0, length_m)
    assert sim.min_gap_aro_m == pytest.approx(10.0, abs=1e-6)
    assert sim.first_contact is None


@pytest.mark.parametrize("length_m", [4.5, 60.0])
def test_contact_with_a_long_obstacle_is_found(length_m):
    """The ego's front 0.5 m inside a trailer's rear is a contact with the obstacle."""
    sim = _checked(-0.5, length_m)
    assert sim.first_contact is not None
    assert sim.first_contact.role == "aro"


def test_a_car_beyond_the_watch_is_not_measured():
    """For a car the watch is as before: centres more than 20 m apart, no gap measured."""
    assert math.isinf(_checked(16.0, 4.5).min_gap_aro_m)
