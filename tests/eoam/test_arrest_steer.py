"""Mode 3's arrest along a turn the tyres sustain (``EoamSettings.arrest_lateral_g``): the
steady-state steer for the lateral acceleration asked, the yaw-rate gain on the error to
a_y / v, never past the front slip envelope's edge; and the setting's validation."""

import pytest

from eoam_sumo.control.steering import understeer_gradient
from eoam_sumo.eoam import EgoMeasurement, EoamSettings
from eoam_sumo.eoam.lateral import arrest_steer
from eoam_sumo.eoam.parts import build_parts
from eoam_sumo.offline.tables import LookupTables, default_tables_dir
from eoam_sumo.params import G_MPS2, ego_e_class_sedan

P = ego_e_class_sedan()
V, MU, G = 40.0, 0.7, 0.9  # 144 km/h on mu 0.7, the arrest at 0.9 mu g


@pytest.fixture(scope="module")
def parts():
    tables = LookupTables.load(default_tables_dir(), params=P)
    return build_parts(P, tables, EoamSettings(arrest_lateral_g=G))


def _meas(yaw_rate_radps: float, vy_mps: float = 0.0) -> EgoMeasurement:
    return EgoMeasurement(0.0, V, vy_mps, yaw_rate_radps, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, MU, 3.5)


def test_at_the_target_yaw_rate_it_steers_the_steady_state_angle(parts):
    """Moving left (arrest +1), turning right at a_y / v = 0.9 mu g / v: the bicycle model's
    steady steer (L + K_us v^2) a_y / v^2, to the right."""
    ay = -G * MU * G_MPS2
    want = (P.wheelbase_m + understeer_gradient(P) * V * V) * ay / (V * V)
    # the body's steady sideslip keeps the front slip inside the envelope
    assert arrest_steer(parts, _meas(ay / V, -0.3), 1.0, G) == pytest.approx(want, rel=1e-9)


def test_yaw_rate_past_the_target_steers_less_and_still_turning_the_other_way_more(parts):
    ay = -G * MU * G_MPS2
    at = arrest_steer(parts, _meas(ay / V, -0.3), 1.0, G)
    assert arrest_steer(parts, _meas(1.5 * ay / V, -0.3), 1.0, G) > at  # less to the right
    assert arrest_steer(parts, _meas(0.5 * ay / V, -0.3), 1.0, G) < at


def test_never_past_the_front_slip_envelope(parts):
    """Still turning left hard: the yaw-rate error asks for more than the envelope allows."""
    edge = parts.steering.envelope_edge(V, 0.4, 0.0, MU, -1.0)
    assert arrest_steer(parts, _meas(0.4), 1.0, G) == pytest.approx(edge)
    # mirrored: moving right, turning right hard
    edge = parts.steering.envelope_edge(V, -0.4, 0.0, MU, 1.0)
    assert arrest_steer(parts, _meas(-0.4), -1.0, G) == pytest.approx(edge)


@pytest.mark.parametrize("bad", [0.0, 1.5, -0.2])
def test_an_arrest_share_outside_0_1_is_refused(bad):
    with pytest.raises(ValueError, match="arrest_lateral_g"):
        EoamSettings(arrest_lateral_g=bad)
