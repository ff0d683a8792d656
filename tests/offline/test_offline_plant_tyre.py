"""The design model plans with the plant's tyre: its lateral dynamics are the plant's.

Independent truth: the plant's own tyre (``plant.tyres``) and right-hand side
(``plant.model.rhs``), which the optimiser never calls.
"""

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from eoam_sumo.offline.design import DesignSettings
from eoam_sumo.offline.model import fiala_lateral_force
from eoam_sumo.params import ego_e_class_sedan
from eoam_sumo.plant.ops import FloatOps
from eoam_sumo.plant.tyres import fiala_lateral_force_n

P = ego_e_class_sedan()
S = DesignSettings()


@given(z=st.floats(-1.0, 1.0), peak=st.floats(100.0, 12000.0))
def test_design_tyre_is_the_plant_fiala_tyre_below_its_peak(z, peak):
    c = P.cornering_stiffness_front_npr
    tan_alpha = 3.0 * peak * z / c
    ours = fiala_lateral_force(tan_alpha, c, peak, math)
    # the plant's sign convention: tan(slip) of the contact patch, force against it
    plant = fiala_lateral_force_n(-tan_alpha, c, peak, FloatOps())
    assert ours == pytest.approx(plant, rel=1e-9, abs=1e-6)
