"""Mobileye's Responsibility-Sensitive Safety, longitudinal (Shalev-Shwartz, Shammah,
Shashua 2017, arXiv:1708.06374, Definition 1), as the JRC's reference code runs it as a
driver (``ec-jrc/JRC-FSM`` ``utility/models.py`` ``RSS_check_safety``/``RSS_react``).

The safe distance of a rear car at ``v_r`` behind a front car at ``v_f``:
``d_min = v_r rho + a_max rho^2 / 2 + (v_r + rho a_max)^2 / (2 b_min) - v_f^2 / (2 b_max)``,
at least 0. Closer than that, the rear car keeps its speed for ``rho`` and then brakes, the
deceleration rising at the careful driver's jerk to 0.774 g, until the front car is no longer
slower nor braking and the distance is safe again, or the rear car stands."""

from __future__ import annotations

from eoam_sumo.drivers.common import Lead, Response, gate_response
from eoam_sumo.drivers.params import RssParams

RSS = RssParams()  # the published parameter set


def rss_safe_distance_m(v_rear_mps: float, v_front_mps: float, p: RssParams = RSS) -> float:
    """Definition 1's minimal safe longitudinal distance [m]."""
    rho, a = p.response_s, p.accel_max_mps2
    d = (
        v_rear_mps * rho
        + 0.5 * a * rho**2
        + (v_rear_mps + rho * a) ** 2 / (2.0 * p.brake_min_mps2)
        - v_front_mps**2 / (2.0 * p.brake_max_mps2)
    )
    return max(d, 0.0)


class RssDriver:
    """RSS as a driver: ``step`` -> acceleration or None (no intervention)."""

    name = "rss"

    def __init__(self, params: RssParams = RSS):
        self.p = p = params
        self.response = Response(p.response_s, 0.0, p.jerk_mps3, p.decel_mps2)

    def reset(self) -> None:
        self.response.stop()

    def step(self, t_s: float, v_mps: float, a_mps2: float, lead: Lead | None, dt_s: float):
        p, resp = self.p, self.response
        unsafe = lead is not None and lead.gap_m < rss_safe_distance_m(v_mps, lead.speed_mps, p)
        state = gate_response(resp, t_s, unsafe, lead, v_mps, p.lead_braking_mps2)
        if state != "on":
            return -p.decel_mps2 if state == "hold" else None
        return resp.accel(t_s, dt_s)
