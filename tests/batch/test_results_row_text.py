"""results.csv's own row formatter writes what pandas' ``to_csv`` of the one-row frame writes,
byte for byte (pandas is the independent truth), for every kind of cell a row holds."""

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from eoam_sumo.batch.results import COLUMNS, csv_text, row_text

_SPECIAL = [math.nan, math.inf, -math.inf, 0.0, -0.0, 1e-5, 1e16, 5e-324, 1e300, 0.1, 3.0]
_CELLS = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(2**70), 2**70),
    st.sampled_from(_SPECIAL),
    st.floats(width=64),
    st.floats(min_value=-1e4, max_value=1e4),
    st.floats(width=64).map(np.float64),
    st.integers(-9, 9).map(np.int64),
    st.booleans().map(np.bool_),
    st.text(max_size=8),
    st.sampled_from(["", "a,b", 'say "x"', "line\nbreak", " lead", "1.0", "True", "nan"]),
)


@settings(max_examples=80, deadline=None)
@given(st.lists(_CELLS, min_size=len(COLUMNS), max_size=len(COLUMNS)))
def test_row_text_is_pandas_to_csv(cells):
    row = dict(zip(COLUMNS, cells))
    assert row_text(row) == csv_text([row], header=False)


def test_a_row_with_missing_keys_leaves_them_empty():
    row = {"case_id": "onc-none_v55_mu0.1", "status": "ok", "ego_speed_kmh": 55}
    assert row_text(row) == csv_text([row], header=False)


def test_row_log_rows_readable_at_once_and_after_close(tmp_path):
    """RowLog: each row is in the file as soon as it is added (before any sync), and all
    of them after close."""
    import pandas as pd

    from eoam_sumo.batch.results import COLUMNS, RowLog

    path = tmp_path / "results.csv"
    log = RowLog(path, pd.DataFrame(columns=list(COLUMNS), dtype=str))
    for k in range(3):
        log.add({"case_id": f"case{k}", "status": "ok"})
        assert path.read_text(encoding="utf-8").count("\ncase") == k + 1
    log.close()
    assert log.fh.closed
    assert path.read_text(encoding="utf-8").count("\ncase") == 3
