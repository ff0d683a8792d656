"""Table 2 against the committed golden files: colours, contact partners, modes and key figures,
and every time series at 10 Hz, within the tolerances that hold on any machine."""

from __future__ import annotations

import pytest

from eoam_sumo.batch.results import RESULTS_FILE, read_results
from eoam_sumo.sim.margins import NEAR_MISS_GAP_M
from tests.golden.table2_golden import run_table2, tolerant_differences

pytestmark = pytest.mark.sumo


def test_table2_matches_the_golden_file(tmp_path):
    diff = tolerant_differences(run_table2(tmp_path))
    assert not diff, (
        "Table 2 differs from the golden files in tests/golden/ (update them deliberately with "
        "`make golden-update` and explain each cell):\n" + "\n".join(diff)
    )
    check_verdicts(read_results(tmp_path / RESULTS_FILE))


def check_verdicts(results) -> None:
    """What every honest Table 2 must show, whatever the colours."""
    assert (results["status"] == "ok").all()
    assert not (results["outcome"] == "unfinished").any()  # every case ends by itself
    hit = results[results["collision_with"] != "none"]
    assert len(hit) > 0
    assert ((hit["contact_overlap"] > 0.0) & (hit["contact_overlap"] <= 1.0)).all()
    assert (hit["delta_v_ego_mps"] > 0.0).all() and (hit["collision_with_id"] != "").all()
    head_on = hit[hit["contact_kind"] == "head_on"]
    ratio = head_on["delta_v_ego_mps"] / head_on["impact_speed_mps"]
    assert ((ratio >= 0.3) & (ratio <= 0.7)).all()
    oncoming = results[results["oncoming_start_m"].notna()]
    assert oncoming["min_gap_oncoming_m"].notna().all()
    assert results[results["oncoming_start_m"].isna()]["min_gap_oncoming_m"].isna().all()
    green = results[results["outcome"] == "green"]
    close = green[
        (green["min_gap_aro_m"] <= NEAR_MISS_GAP_M)
        | (green["min_gap_oncoming_m"] <= NEAR_MISS_GAP_M)
    ]
    assert (close["near_miss"] == "True").all()
    # the lane changes that ended green passed the obstacle they avoided (the ARO)
    changed = green[green["time_in_opposite_lane_s"] > 0.0]
    assert len(changed) > 0 and (changed["passed_obstacle"] == "True").all()
