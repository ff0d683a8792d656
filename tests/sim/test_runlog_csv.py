"""timeseries.csv's own formatter writes what pandas' ``to_csv(float_format="%.9g")`` of the
same table writes, byte for byte (pandas is the independent truth)."""

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from eoam_sumo.sim.runlog import _INT_COLUMNS, COLUMNS, csv_text, table_frame

_SPECIAL = [math.nan, math.inf, -math.inf, 0.0, -0.0, 1e-300, 5e-324, 1e300, 123456789.5]
_FLOATS = st.one_of(
    st.sampled_from(_SPECIAL),
    st.floats(allow_nan=False, allow_infinity=False, width=64),
    st.floats(min_value=-1e4, max_value=1e4),
)
_INTS = st.one_of(st.just(math.nan), st.just(-0.0), st.integers(-3, 9).map(float))
_SECTORS = st.one_of(st.just(math.nan), st.sampled_from("ABCDEFG").map(lambda c: float(ord(c))))


def _column(name: str):
    if name in _INT_COLUMNS:
        return _INTS
    return _SECTORS if name == "sector" else _FLOATS


_ROW = st.tuples(*(_column(c) for c in COLUMNS))


def _pandas(array: np.ndarray) -> str:
    return table_frame(array).to_csv(index=False, float_format="%.9g")


@settings(max_examples=60, deadline=None)
@given(st.lists(_ROW, min_size=0, max_size=12))
def test_csv_text_is_pandas_to_csv(rows):
    array = np.array(rows, dtype=float).reshape(-1, len(COLUMNS))
    assert csv_text(array) == _pandas(array)


def test_csv_text_of_a_logged_shape():
    """A run-like table: a time column, empty radar columns before a detection, no sector at
    the start, negative zeros."""
    n = 300
    rng = np.random.default_rng(7)
    array = rng.normal(0.0, 30.0, (n, len(COLUMNS)))
    array[:, 0] = np.arange(n) * 0.01
    for c in _INT_COLUMNS:
        array[:, COLUMNS.index(c)] = rng.integers(0, 5, n)
    array[:100, COLUMNS.index("aro_range_m")] = math.nan
    array[:50, COLUMNS.index("sector")] = math.nan
    array[50:, COLUMNS.index("sector")] = ord("D")
    array[::7, COLUMNS.index("vy_mps")] = -0.0
    text = csv_text(array)
    assert text == _pandas(array)
    assert text.splitlines()[1].split(",")[COLUMNS.index("aro_range_m")] == ""
