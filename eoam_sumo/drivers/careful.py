"""UN R157 (ALKS) Annex 4, Appendix 3: the competent and careful human driver.

A risk is perceived ``perception_s`` (0.4 s) after it appears: a vehicle revealed ahead (a
cut-out; closing faster than 1 m/s: a car first seen ahead at about the ego's speed is none)
or the lead braking. A car cutting in is perceived when the forward radar classes it in the
path: 0.4 s after it crossed the lateral wandering threshold of 0.375 m
(``sensing.radar.cutting_in``, ``CUT_IN_PERCEPTION_S``: the radar holds R157's perception
for every controller). A cut-in is then critical only when TTC < 2 s (esmini
``ReferenceDriver::CheckCriticalCutIn``, JRC-FSM ``CC_check_safety_cut_in``: the time headway
gates esmini's cut-out and deceleration, not the cut-in);
a revealed vehicle or a braking lead always is (JRC-FSM ``CC_check_safety``). The driver
reacts for ``reaction_s`` (0.75 s) coasting at 0.4 m/s^2, then brakes, the deceleration
rising from 0.4 m/s^2 to 0.774 g at 12.65 m/s^3 (0.774 g in 0.6 s), until the lead is no
longer closing and no longer braking, or the ego stands.
"""

from __future__ import annotations

from eoam_sumo.drivers.common import STOPPED_MPS, Lead, Response, released, time_to_collision_s
from eoam_sumo.drivers.params import CarefulDriverParams

CAREFUL = CarefulDriverParams()  # the published parameter set


class CarefulDriver:
    """The careful driver's longitudinal decision: ``step`` -> acceleration or None (no
    intervention: the cruise holds its speed)."""

    name = "r157-cc"

    def __init__(self, params: CarefulDriverParams = CAREFUL):
        self.p = p = params
        self.response = Response(p.reaction_s, -p.coast_mps2, p.jerk_mps3, p.decel_mps2)
        self.reset()

    def reset(self) -> None:
        self.perceived_at_s: float | None = None  # when the risk is perceived
        self.gated = False  # a cut-in: critical only below the TTC
        self.response.stop()

    def critical(self, lead: Lead, v_mps: float) -> bool:
        return time_to_collision_s(lead, v_mps) < self.p.critical_ttc_s

    def step(self, t_s: float, v_mps: float, a_mps2: float, lead: Lead | None, dt_s: float):
        p, resp = self.p, self.response
        if resp.active:
            if v_mps < STOPPED_MPS:
                return -p.decel_mps2
            if released(lead, v_mps, p.lead_braking_mps2):
                self.reset()
                return None
            return resp.accel(t_s, dt_s)
        if lead is None:
            self.perceived_at_s = None
            return None
        risk = lead.fresh and (lead.from_side or v_mps - lead.speed_mps > p.closing_mps)
        if self.perceived_at_s is None and (risk or lead.accel_mps2 < -p.lead_braking_mps2):
            self.gated = cut_in = lead.fresh and lead.from_side
            self.perceived_at_s = t_s + (0.0 if cut_in else p.perception_s)
        if lead.accel_mps2 < -p.lead_braking_mps2:
            self.gated = False  # the lead brakes: a risk whatever its distance
        if self.perceived_at_s is None or t_s < self.perceived_at_s - 1e-9:
            return None
        if self.gated and not self.critical(lead, v_mps):
            return None
        resp.start(t_s)
        return resp.accel(t_s, dt_s)
