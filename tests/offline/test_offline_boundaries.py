"""Stopping and clearing distances and buffers (paper eqs. 30-34) against closed forms."""

import math

import numpy as np
import pytest

from eoam_sumo.offline.boundaries import (
    clearing_distance_m,
    constant_speed_clearing_distance_m,
    max_decel_no_lock_mps2,
    steer_buffered_m,
    stop_buffered_m,
    stop_distance_m,
)
from eoam_sumo.offline.design import DesignSettings
from eoam_sumo.offline.model import axle_loads
from eoam_sumo.params import G_MPS2, ego_e_class_sedan

P = ego_e_class_sedan()
S = DesignSettings()
W = 0.5 * (P.width_m + S.obstacle_width_m)


@pytest.mark.parametrize("mu", [1.2, 1.0, 0.7, 0.5, 0.3, 0.1, 0.05])
def test_no_lock_deceleration_matches_brute_force_and_stays_below_mu_g(mu):
    decel = np.linspace(0.0, 15.0, 150001)
    fz_f, fz_r = axle_loads(-decel, P)
    m, phi = P.mass_kg, P.brake_front_share
    ok = (
        (phi * m * decel <= mu * fz_f)
        & ((1 - phi) * m * decel <= mu * fz_r)
        & (m * decel <= P.max_brake_force_n)
    )
    brute = decel[ok].max()
    a = max_decel_no_lock_mps2(P, mu)
    assert a == pytest.approx(brute, abs=2e-4)
    assert a < mu * G_MPS2


def test_stopping_distance_is_closed_form_and_above_the_friction_floor():
    for mu in (1.0, 0.7, 0.3, 0.1):
        a = max_decel_no_lock_mps2(P, mu)
        for v in (5.0, 25.0, 48.0):
            assert stop_distance_m(v, a) == pytest.approx(v * v / (2 * a))
            assert stop_distance_m(v, a) >= v * v / (2 * mu * G_MPS2)
    with pytest.raises(ValueError):
        stop_distance_m(10.0, 0.0)


def test_clearing_distance_of_a_straight_lateral_translation():
    """No yaw, y = c t, x = v t: the corner reaches w_obj/2 when y = w, x_c = x + d_f."""
    t = np.linspace(0.0, 3.0, 301)
    v, c = 20.0, 1.5
    d = clearing_distance_m(v * t, c * t, 0 * t, P, S.obstacle_width_m)
    assert d == pytest.approx(v * W / c + P.cg_to_front_bumper_m, rel=1e-9)


def test_clearing_distance_with_constant_heading_matches_closed_form():
    psi = 0.1
    s = np.linspace(0.0, 40.0, 4001)
    x, y = s * math.cos(psi), s * math.sin(psi)
    d = clearing_distance_m(x, y, np.full_like(s, psi), P, S.obstacle_width_m)
    half = 0.5 * P.width_m
    # y + d_f sin(psi) - half cos(psi) = w_obj / 2 along the line y = x tan(psi)
    y_c = 0.5 * S.obstacle_width_m - P.cg_to_front_bumper_m * math.sin(psi) + half * math.cos(psi)
    x_c = y_c / math.tan(psi) + P.cg_to_front_bumper_m * math.cos(psi) + half * math.sin(psi)
    assert d == pytest.approx(x_c, rel=1e-6)


def test_clearing_distance_raises_when_never_clear():
    t = np.linspace(0.0, 1.0, 11)
    with pytest.raises(ValueError, match="never clears"):
        clearing_distance_m(10 * t, 0.1 * t, 0 * t, P, S.obstacle_width_m)


@pytest.mark.parametrize("mu", [1.0, 0.7, 0.3, 0.1])
def test_constant_speed_clearing_is_above_the_point_mass_bound(mu):
    last = 0.0
    for v_kmh in (20, 55, 90, 120, 165):
        v = v_kmh / 3.6
        d = constant_speed_clearing_distance_m(v, mu, P, S)
        assert d >= v * math.sqrt(2 * W / (mu * G_MPS2))
        assert d > last
        last = d


def test_buffers_add_time_headway_and_constant():
    assert steer_buffered_m(10.0, 20.0, S) == pytest.approx(
        10.0 + 20.0 * S.steer_buffer_time_s + S.steer_buffer_m
    )
    assert stop_buffered_m(30.0, 20.0, S) == pytest.approx(
        30.0 + 20.0 * S.brake_buffer_time_s + S.brake_buffer_m
    )


def test_ttc_per_friction_follows_the_paper_and_interpolates():
    assert [S.ttc_s(m) for m in (1.0, 0.7, 0.3, 0.1)] == [2.5, 2.5, 5.0, 20.0]
    assert S.ttc_s(0.2) == pytest.approx(12.5)
    assert S.ttc_s(0.5) == pytest.approx(3.75)
    assert S.ttc_s(1.2) == 2.5 and S.ttc_s(0.05) == 20.0
