"""The JRC Fuzzy Safety Model (Mattas et al. 2020, Accid. Anal. Prev. 148, 105794), as the
JRC's reference code (``ec-jrc/JRC-FSM``, ``utility/fuzzy_functs.py``, ``utility/models.py``
``FSM_check_safety``/``FSM_react``) runs it as a driver.

Two surrogate safety metrics in [0, 1]: the Proactive Fuzzy Safety (PFS: the gap against the
distance needed if the leader brakes at its hardest, eq. 3-5 of the paper) and the Critical
Fuzzy Safety (CFS: the gap against the distance needed to match the leader's speed, eq.
6-8). The follower is unsafe when PFS + CFS > 0; after ``reaction_s`` at constant speed it
brakes with the deceleration rising at the careful driver's jerk to the fuzzy demand,
``br_min + CFS (br_max - br_min)`` when CFS > 0, else ``PFS br_min``, at most 0.774 g."""

from __future__ import annotations

from eoam_sumo.drivers.common import Lead, Response, gate_response
from eoam_sumo.drivers.params import FsmParams

FSM = FsmParams()  # the published parameter set


def _ramp(dist: float, safe: float, unsafe: float) -> float:
    """1 at or below ``unsafe``, 0 above ``safe``, linear between."""
    if dist > safe:
        return 0.0
    if dist < unsafe:
        return 1.0
    return (dist - safe) / (unsafe - safe)


def pfs(dist_m: float, ur: float, ul: float, p: FsmParams) -> float:
    """Proactive Fuzzy Safety of a follower at ``ur`` behind a leader at ``ul``."""
    dist = dist_m - p.margin_m
    base = ur * p.reaction_s - ul**2 / (2.0 * p.bl_mps2)
    safe = base + ur**2 / (2.0 * p.br_min_mps2) + p.margin_safe_m
    unsafe = base + ur**2 / (2.0 * p.br_max_mps2)
    return _ramp(dist, safe, unsafe)


def cfs(dist_m: float, ur: float, ul: float, ar: float, p: FsmParams) -> float:
    """Critical Fuzzy Safety; ``ar`` the follower's own acceleration now."""
    if ur <= ul:
        return 0.0
    rt = p.reaction_s
    ar_f = max(ar, -p.br_min_mps2)  # a very hard deceleration is not counted on
    u_new = ur + rt * ar_f  # the follower's speed after its reaction time
    if u_new < ul:
        return 1.0 if dist_m < (ur - ul) ** 2 / abs(2.0 * ar) else 0.0
    base = (ur + ar_f * rt / 2.0 - ul) * rt
    rel = (u_new - ul) ** 2
    return _ramp(dist_m, base + rel / (2.0 * p.br_min_mps2), base + rel / (2.0 * p.br_max_mps2))


def fsm_distance_m(speed_mps: float, p: FsmParams = FSM) -> float:
    """The gap at which a follower behind a leader at its own speed is just safe (PFS = 0;
    JRC ``FSM_distance``)."""
    u = speed_mps
    return (
        u * p.reaction_s
        + u**2 / (2 * p.br_min_mps2)
        - u**2 / (2 * p.bl_mps2)
        + (p.margin_safe_m + p.margin_m)
    )


class FsmDriver:
    """The FSM as a driver: ``step`` -> acceleration or None (no intervention)."""

    name = "fsm"

    def __init__(self, params: FsmParams = FSM):
        self.p = p = params
        self.response = Response(p.reaction_s, 0.0, p.jerk_mps3, p.decel_mps2)
        self.cfs = self.pfs = 0.0

    def reset(self) -> None:
        self.response.stop()
        self.cfs = self.pfs = 0.0

    def step(self, t_s: float, v_mps: float, a_mps2: float, lead: Lead | None, dt_s: float):
        p, resp = self.p, self.response
        if lead is None:
            self.cfs = self.pfs = 0.0
        else:
            self.cfs = cfs(lead.gap_m, v_mps, lead.speed_mps, a_mps2, p)
            self.pfs = pfs(lead.gap_m, v_mps, lead.speed_mps, p)
        unsafe = self.cfs + self.pfs > 0.0
        state = gate_response(resp, t_s, unsafe, lead, v_mps, p.lead_braking_mps2)
        if state != "on":
            return -p.decel_mps2 if state == "hold" else None
        if self.cfs > 0.0:
            demand = self.cfs * (p.br_max_mps2 - p.br_min_mps2) + p.br_min_mps2
        else:
            demand = self.pfs * p.br_min_mps2
        return resp.accel(t_s, dt_s, demand)
