"""Table 2 against the committed golden file: colours, key figures and every time series."""

from __future__ import annotations

import pytest

from tests.golden.table2_golden import differences, expected, observed

pytestmark = pytest.mark.sumo


def test_table2_matches_the_golden_file(tmp_path):
    diff = differences(observed(tmp_path), expected())
    assert not diff, (
        "Table 2 differs from tests/golden/table2_expected.csv (update it deliberately with "
        "`python -m tests.golden.table2_golden --update` and explain each cell):\n"
        + "\n".join(diff))
