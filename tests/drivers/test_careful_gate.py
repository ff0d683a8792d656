"""The careful driver's criticality (R157 Annex 4 App. 3 as esmini and JRC-FSM run it): a car
cutting in (perceived when the radar classes it in path, which holds R157's 0.4 s) is acted
on only when TTC < 2 s (esmini's ``CheckCriticalCutIn``, JRC-FSM's ``CC_check_safety_cut_in``:
not on the headway); a vehicle revealed ahead is acted on once perceived (0.4 s), whatever its
distance."""

from __future__ import annotations

from eoam_sumo.drivers.careful import CarefulDriver
from eoam_sumo.drivers.common import Lead

DT = 0.01
V = 100 / 3.6


def first_reaction_s(lead_at, t_end=6.0):
    """When the driver first asks for an acceleration (None: never), the ego held at ``V``."""
    driver = CarefulDriver()
    for k in range(round(t_end / DT)):
        t = k * DT
        if driver.step(t, V, 0.0, lead_at(t, k), DT) is not None:
            return t
    return None


def test_a_close_cut_in_is_acted_on_when_the_radar_reports_it():
    # 8 m ahead, 5 m/s slower (TTC 1.6 s): the radar's report is the perception
    t = first_reaction_s(lambda t, k: Lead(8.0, V - 5.0, 0.0, k == 10, True))
    assert t is not None and abs(t - 0.1) < 1e-6


def test_a_cut_in_far_enough_ahead_is_not_acted_on():
    # 60 m ahead at 5 m/s slower: TTC 10.8 s, headway 2.2 s, throughout (held for the test)
    assert first_reaction_s(lambda t, k: Lead(60.0, V - 5.0, 0.0, k == 10, True)) is None


def test_a_cut_in_becomes_critical_below_a_2_s_ttc_not_on_its_headway():
    # 60 m ahead closing at 5 m/s: perceived at 0.1 s, not critical then (TTC 12 s); its
    # headway falls below 2 s (55.56 m) after 0.889 s, which is not a trigger (the driver
    # braked at 0.78 g for cut-ins with a TTC of 4.6-7.2 s); the TTC falls below 2 s (10 m)
    # after 10 s: the reaction starts then
    def lead(t, k):
        return Lead(60.0 - 5.0 * t, V - 5.0, 0.0, k == 10, True)

    t = first_reaction_s(lead, t_end=12.0)
    assert t is not None and abs(t - 10.01) < 1e-6


def test_a_revealed_car_is_acted_on_once_perceived_whatever_its_distance():
    # a stopped car revealed 90 m ahead (TTC 3.2 s, headway 3.2 s) at 0.1 s
    t = first_reaction_s(lambda t, k: Lead(90.0 - V * t, 0.0, 0.0, k == 10, False))
    assert t is not None and abs(t - 0.5) < 1e-6


def test_a_car_first_seen_ahead_at_the_ego_s_speed_is_no_risk():
    # a tracker confirming the lead late: a new object 40 m ahead, as fast as the ego
    assert first_reaction_s(lambda t, k: Lead(40.0, V, 0.0, k == 10, False)) is None
