"""The reference drivers' parameters: frozen dataclasses, a unit and a source per value.

Sources (docs/reference-drivers.md):

* UN R157 (ALKS), Annex 4, Appendix 3, the "competent and careful human driver"; the values
  as the two public implementations give them: esmini
  ``EnvironmentSimulator/Modules/Controllers/ControllerALKS_R157SM.hpp`` (``ReferenceDriver``)
  and the JRC's ``ec-jrc/JRC-FSM`` ``utility/vehicle.py`` (``CC_human_driver``);
* Mattas et al. 2020, "Fuzzy Surrogate Safety Metrics for real-time assessment of rear-end
  collision risk", Accid. Anal. Prev. 148, 105794; parameters of ``ec-jrc/JRC-FSM``
  ``utility/vehicle.py`` (``FSM_*``);
* Shalev-Shwartz, Shammah, Shashua 2017, "On a formal model of safe and scalable
  self-driving cars", arXiv:1708.06374, Definition 1 (safe longitudinal distance);
  parameters of ``ec-jrc/JRC-FSM`` ``utility/vehicle.py`` (``RSS_*``, ``max_a``, ``max_d``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from mypy_extensions import mypyc_attr

from eoam_sumo.params import G_MPS2

#: 0.774 g, the careful driver's full deceleration (esmini ``ReferenceDriver``: 0.774 * 9.81;
#: JRC ``CC_max_deceleration``), here on the project's g.
CAREFUL_DECEL_MPS2 = 0.774 * G_MPS2
#: reached in 0.6 s from 0 (R157 Annex 4 App. 3; esmini ``min_jerk_`` 12.65 m/s^3 = 7.59 / 0.6)
CAREFUL_JERK_MPS3 = CAREFUL_DECEL_MPS2 / 0.6


def _check_positive(obj) -> None:
    for f in fields(obj):
        v = getattr(obj, f.name)
        if not (math.isfinite(v) and v >= 0.0):
            raise ValueError(f"{type(obj).__name__}.{f.name}={v!r} must be finite and >= 0")


@mypyc_attr(native_class=False)
@dataclass(frozen=True)
class CarefulDriverParams:
    """UN R157 Annex 4 Appendix 3, the competent and careful human driver."""

    perception_s: float = 0.4  # [s] risk perception time (esmini ``perception_time_``)
    wandering_m: float = 0.375  # [m] lateral wandering threshold (esmini; sensing.radar)
    reaction_s: float = 0.75  # [s] reaction time (esmini ``Model(..., 0.75, ...)``; JRC CC_rt)
    coast_mps2: float = 0.4  # [m/s^2] deceleration while reacting, foot off the accelerator
    #                          (esmini ``release_deceleration_``; JRC CC_release_deceleration)
    decel_mps2: float = CAREFUL_DECEL_MPS2  # [m/s^2] full braking, 0.774 g
    jerk_mps3: float = CAREFUL_JERK_MPS3  # [m/s^3] 0.774 g reached in 0.6 s
    critical_ttc_s: float = 2.0  # [s] a cut-in critical below this TTC (esmini ``critical_ttc_``)
    lead_braking_mps2: float = 1.0  # [m/s^2] a lead braking harder is a risk (assumption)
    closing_mps: float = 1.0  # [m/s] a car revealed ahead closing faster is a risk (assumption)

    def __post_init__(self) -> None:
        _check_positive(self)


@mypyc_attr(native_class=False)
@dataclass(frozen=True)
class FsmParams:
    """Fuzzy Safety Model (Mattas et al. 2020; JRC-FSM ``utility/vehicle.py``)."""

    reaction_s: float = 0.75  # [s] FSM_rt
    br_min_mps2: float = 4.0  # [m/s^2] FSM_br_min, comfortable braking of the follower
    br_max_mps2: float = 6.0  # [m/s^2] FSM_br_max, the follower's hardest braking
    bl_mps2: float = 7.0  # [m/s^2] FSM_bl, the leader's hardest braking
    margin_m: float = 2.0  # [m] FSM_margin_dist (taken off the gap)
    margin_safe_m: float = 2.0  # [m] FSM_margin_safe_dist (added to the safe distance)
    decel_mps2: float = CAREFUL_DECEL_MPS2  # [m/s^2] FSM_max_deceleration, 0.774 g
    jerk_mps3: float = CAREFUL_JERK_MPS3  # [m/s^3] CC_min_jerk (JRC FSM_react uses it)
    lead_braking_mps2: float = 1.0  # [m/s^2] a lead braking harder keeps the brake on (assumption)

    def __post_init__(self) -> None:
        _check_positive(self)
        if not 0.0 < self.br_min_mps2 < self.br_max_mps2:
            raise ValueError("FsmParams: need 0 < br_min_mps2 < br_max_mps2")


@mypyc_attr(native_class=False)
@dataclass(frozen=True)
class RssParams:
    """RSS safe longitudinal distance (Shalev-Shwartz et al. 2017, Def. 1; JRC-FSM values)."""

    response_s: float = 0.75  # [s] rho, RSS_rt
    accel_max_mps2: float = 3.0  # [m/s^2] a_max,accel of the rear car during rho (max_a)
    brake_min_mps2: float = 6.0  # [m/s^2] b_min,brake of the rear car (max_d)
    brake_max_mps2: float = 6.0  # [m/s^2] b_max,brake of the front car (max_d)
    decel_mps2: float = CAREFUL_DECEL_MPS2  # [m/s^2] the response's braking, RSS_max_deceleration
    jerk_mps3: float = CAREFUL_JERK_MPS3  # [m/s^3] RSS_min_jerk
    lead_braking_mps2: float = 1.0  # [m/s^2] a lead braking harder keeps the brake on (assumption)

    def __post_init__(self) -> None:
        _check_positive(self)
