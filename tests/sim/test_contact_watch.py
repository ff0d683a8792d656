"""The contact check and the obstacle's gap watch road users of any length (no SUMO)."""

from __future__ import annotations

import math

import pytest

from eoam_sumo.plant import initial_state
from eoam_sumo.sim.cosim import CoSimulation
from eoam_sumo.sim.roadframe import RoadFrame
from eoam_sumo.sim.settings import RunSettings
from eoam_sumo.world.bodies import Body


def _checked(
    front_gap_m: float, length_m: float, yaw_rad: float = 0.0, speed_mps: float = 0.0
) -> CoSimulation:
    """A standing ego at the origin heading +x and a road user ``length_m`` long (standing,
    or moving at ``speed_mps`` heading ``yaw_rad``) whose rear is ``front_gap_m`` ahead of
    the ego's front bumper, in its lane; the contact check run once."""
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
    if yaw_rad:  # across the lane: its side faces the ego, ``front_gap_m`` ahead
        centre_x_m = p.cg_to_front_bumper_m + front_gap_m + 1.25
    other = Body("obstacle", "trailer", centre_x_m, 0.0, yaw_rad, speed_mps, length_m, 2.5)
    sim.bodies = sim.bodies_before = [other]
    sim.first_contact, sim.min_gap_aro_m = None, math.inf
    sim._gaps, sim._gaps_pose, sim._met_ahead, sim._obstacles = {}, None, {}, set()
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


def test_a_car_crossing_the_lane_at_a_junction_is_not_the_obstacle():
    """A car crossing the ego's lane from the side (heading north at 15 m/s), hit with the
    ego's front, is another road user, not the ARO (docs/outcomes.md, Roles)."""
    sim = _checked(-0.3, 4.5, math.pi / 2, 15.0)
    assert sim.first_contact is not None
    assert sim.first_contact.role == "other"
    assert math.isinf(sim.min_gap_aro_m)
