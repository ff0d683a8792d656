"""The EOAM's no-lock brake limit on the fixed brake split (``control.brake_split``) against
eq. 33's closed form and against the plant's own wheels.

Independent truths: eq. 33's axle balance ``z = mu b / (phi L - mu h)`` (and the rear's),
which the limit must reduce to without the chassis terms (rolling resistance, the tyre's load
sensitivity, cornering); the plant, braked straight with that command, whose wheels must not
lock below the limit and must lock a little above it.
"""

import dataclasses

import numpy as np
import pytest

from eoam_sumo.control import brake_split, equivalent_mass_kg
from eoam_sumo.control.longitudinal import LongitudinalController
from eoam_sumo.offline.boundaries import max_decel_no_lock_mps2
from eoam_sumo.params import G_MPS2, PLANT_TYRE_FNOMIN_N
from eoam_sumo.plant import OUTPUT_NAMES, Plant, initial_state
from eoam_sumo.vehicle_files import load_vehicle

Y = {name: i for i, name in enumerate(OUTPUT_NAMES)}
V0_MPS = 100.0 / 3.6


@pytest.mark.parametrize("mu", [0.1, 0.3, 0.7, 1.0])
@pytest.mark.parametrize("name", ["sedan", "sedan-r13h"])
def test_without_the_chassis_terms_the_limit_is_eq_33(monkeypatch, name, mu):
    monkeypatch.setattr(brake_split, "PLANT_TYRE_PEAK_LOAD_SENSITIVITY", 0.0)
    p = dataclasses.replace(load_vehicle(name), rolling_resistance_coeff=0.0)
    limit = brake_split.BrakeSplit(p).limit_n(mu, 0.0, 0.0, 0.0, p.mass_kg)
    assert limit == pytest.approx(p.mass_kg * max_decel_no_lock_mps2(p, mu), rel=1e-9)


def test_cornering_and_load_transfer_lower_the_limit(params):
    m_eq = equivalent_mass_kg(params)
    straight = brake_split.BrakeSplit(params).limit_n(0.3, 0.0, 300.0, 0.0, m_eq)
    turning = brake_split.BrakeSplit(params).limit_n(0.3, 1.5, 300.0, 0.5, m_eq)
    assert 0.0 < turning < np.sqrt(1.0 - 0.5**2) * straight
    assert brake_split.BrakeSplit(params).limit_n(0.3, 2.9, 300.0, 1.0, m_eq) == 0.0


def _locked_while_moving(plant, mu, brake_n):
    """True if an axle locks (the plant's flags) while vx > 3 m/s, braking straight."""
    x = initial_state(0.0, 0.0, 0.0, V0_MPS, params=plant.params).tolist()
    while x[3] > 3.0:
        x, y = plant.advance(x, (0.0, 0.0, brake_n), mu)
        if y[Y["front_locked"]] or y[Y["rear_locked"]]:
            return True
    return False


def _assert_the_limit_is_sharp(plant, params, mu):
    """No lock at 0.99 of the lowest limit (the slow end, where drag has gone), a lock at 1.05
    of the highest (at the start speed)."""
    ctrl = LongitudinalController(params)
    rolling_n = params.rolling_resistance_coeff * params.mass_kg * G_MPS2
    m_eq = equivalent_mass_kg(params)
    low = brake_split.BrakeSplit(params).limit_n(mu, 0.0, rolling_n, 0.0, m_eq)
    high = brake_split.BrakeSplit(params).limit_n(mu, 0.0, ctrl.resistance_n(V0_MPS), 0.0, m_eq)
    assert not _locked_while_moving(plant, mu, 0.99 * low)
    assert _locked_while_moving(plant, mu, 1.05 * high)


@pytest.mark.parametrize("mu", [0.1, 0.3])
def test_the_plant_locks_just_above_the_limit_and_not_below(params, plant_cache_dir, mu):
    plant = Plant(params, cache_dir=plant_cache_dir)
    _assert_the_limit_is_sharp(plant, params, mu)
    # eq. 33's no-lock force itself locks the front on ice
    assert _locked_while_moving(
        plant, 0.1, 0.95 * params.mass_kg * max_decel_no_lock_mps2(params, 0.1)
    )


@pytest.mark.parametrize("mu", [0.3, 0.7])
def test_a_light_car_s_limit_uses_its_own_tyre(plant_cache_dir, mu):
    """The compact's tyres are scaled to its own nominal load (the plant's MF LFZO), not the
    set's 4850 N: taken about 4850 N its loaded front tyres would look grippier than they are,
    and the command at 0.99 of that limit locked its front axle (with its 3010 N tyre then:
    Table 2's lane changes began on locked front wheels)."""
    params = dataclasses.replace(load_vehicle("compact"), abs_fitted=False, esc_fitted=False)
    assert params.tyre_nominal_load_n != PLANT_TYRE_FNOMIN_N  # the case this test is about
    _assert_the_limit_is_sharp(Plant(params, cache_dir=plant_cache_dir), params, mu)
