"""The settle test of modes 3 and 5 and of the early return on a curve: the heading a car
keeps in steady cornering is off the road's by minus its sideslip, kappa (b - m a v^2 /
(L C_r)) of the linear single-track model (Rajamani 2012 sec. 3.3), and a car that holds
its lane on a 300 m curve at 150 km/h is settled there."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from eoam_sumo.control.steering import SteeringController
from eoam_sumo.eoam import EgoMeasurement, EoamSettings
from eoam_sumo.eoam.strategies import heading_settled
from eoam_sumo.params import ego_e_class_sedan

PARAMS = ego_e_class_sedan()
SETTINGS = EoamSettings()
STEERING = SteeringController(PARAMS, SETTINGS.steering, SETTINGS.preview_time_s)


def _meas(speed_mps: float, curvature_1pm: float, e_yaw_rad: float) -> EgoMeasurement:
    return EgoMeasurement(
        time_s=0.0,
        vx_mps=speed_mps,
        vy_mps=0.0,
        yaw_rate_radps=speed_mps * curvature_1pm,
        ax_mps2=0.0,
        ay_mps2=speed_mps * speed_mps * curvature_1pm,
        s_m=0.0,
        d_m=0.0,
        e_yaw_rad=e_yaw_rad,
        road_curvature_1pm=curvature_1pm,
        mu=1.0,
        lane_width_m=3.5,
    )


def _steady_heading_rad(speed_mps: float, curvature_1pm: float) -> float:
    """Minus the linear single-track sideslip, from the parameters directly."""
    p = PARAMS
    slip = p.mass_kg * p.cg_to_front_m / (p.wheelbase_m * p.cornering_stiffness_rear_npr)
    return -curvature_1pm * (p.cg_to_rear_m - slip * speed_mps * speed_mps)


@pytest.mark.parametrize("curvature_1pm", [1.0 / 300.0, -1.0 / 300.0])
def test_steady_cornering_on_a_300_m_curve_at_150_kmh_is_settled(curvature_1pm):
    speed = 150.0 / 3.6
    heading = _steady_heading_rad(speed, curvature_1pm)
    assert abs(heading) > SETTINGS.settle_heading_rad  # the old test never settled here
    assert heading_settled(SETTINGS, STEERING, _meas(speed, curvature_1pm, heading))
    assert not heading_settled(SETTINGS, STEERING, _meas(speed, curvature_1pm, -heading))


@given(
    speed=st.floats(0.0, 50.0),
    e_yaw=st.floats(-0.1, 0.1),
)
def test_on_a_straight_road_it_is_the_heading_alone(speed, e_yaw):
    settled = heading_settled(SETTINGS, STEERING, _meas(speed, 0.0, e_yaw))
    assert settled == (abs(e_yaw) <= SETTINGS.settle_heading_rad)


def test_the_steady_heading_is_the_single_track_models():
    speed, curvature = 30.0, 1.0 / 200.0
    beta = STEERING.steady_sideslip(speed, curvature)
    assert -beta == pytest.approx(_steady_heading_rad(speed, curvature), rel=1e-9)
    assert math.isfinite(beta)
