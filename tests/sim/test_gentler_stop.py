"""A gentler stop of the obstacle never ends worse: real co-simulations on the baseline.

At 100 and 130 km/h, mu 1.0 and 0.7, oncoming traffic at 300 m, the obstacle stopping at
8, 6, 4, 3 and 2 m/s^2: the impact speed never grows as the stop gets gentler (the decision
uses the obstacle's deceleration measured from the range rate). With the paper's rule (the
closing speed as if the obstacle held it) it did: 100 km/h, mu 1.0 gave no contact at
8 m/s^2 and 9.7 / 11.1 m/s impacts at 4 / 3 m/s^2.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from eoam_sumo.batch.runner import run_batch

pytestmark = pytest.mark.sumo

REPO = Path(__file__).resolve().parents[2]
DECELS = (8.0, 6.0, 4.0, 3.0, 2.0)


def test_gentler_obstacle_stop_never_ends_with_a_higher_impact_speed(tmp_path):
    matrix = tmp_path / "decel.toml"
    matrix.write_text(
        f'[scenario]\nsumocfg = "{REPO / "scenarios" / "baseline.sumocfg"}"\n'
        "max_time_s = 20.0\n"
        "[sweep]\nego_speed_kmh = [100, 130]\nmu = [1.0, 0.7]\noncoming_start_m = [300]\n"
        f"aro_decel_mps2 = {list(DECELS)}\n"
    )
    results = run_batch(matrix, tmp_path / "out", jobs=2, progress=False)
    assert (results["status"] == "ok").all()
    for (speed, mu), group in results.groupby(["ego_speed_kmh", "mu"]):
        impact = group.set_index("aro_decel_mps2").loc[list(DECELS), "impact_speed_mps"]
        impact = impact.fillna(0.0).tolist()
        for harder, gentler, a_hard, a_gentle in zip(impact, impact[1:], DECELS, DECELS[1:]):
            assert gentler <= harder + 0.05, (
                f"{speed:g} km/h, mu {mu:g}: a {a_gentle:g} m/s^2 stop hit at {gentler:.2f} m/s, "
                f"a {a_hard:g} m/s^2 one at {harder:.2f} m/s"
            )
