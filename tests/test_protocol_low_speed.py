"""The EOAM with its lane change (``--system eoam``) at the low speeds of Euro NCAP's CCRs and
CCRb: where stopping is shorter than clearing it brakes in its lane (``decision.dmm``), so it
never swings round the target into its side."""

from __future__ import annotations

import pandas as pd
import pytest

from eoam_sumo.cli import main

pytestmark = pytest.mark.sumo

#: Points that changed lanes and hit the target before the rule: CCRs 20 km/h at 125 %
#: offset (side contact at 4.4 m/s), CCRs 30 km/h at 100 % (offset front hit at 5.2 m/s),
#: CCRb 30 km/h behind a target braking at 4 m/s^2 (side contact at 5.2 m/s).
POINTS = "^(CCRs_v20_t0_o125|CCRs_v30_t0_o100|CCRb_v30_t30_o100_g8p3_d4)"


def test_at_low_speed_the_eoam_brakes_in_its_lane_and_touches_nothing(tmp_path):
    out = tmp_path / "out"
    args = ["protocol", "euroncap-aeb-c2c-2026", "--system", "eoam", "--points", POINTS]
    status = main([*args, "--out", str(out), "--jobs", "1", "--no-progress"])
    assert status == 0
    rows = pd.read_csv(out / "results.csv")
    assert len(rows) == 3 and set(rows["status"]) == {"ok"}
    assert set(rows["collision_with"]) == {"none"}
    assert set(rows["modes_visited"].astype(str)) == {"0-1"}  # braking only, never steering
    assert rows["max_lateral_offset_m"].abs().max() < 0.1
    assert (rows["min_gap_aro_m"] > 0.5).all()
