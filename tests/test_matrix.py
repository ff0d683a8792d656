"""Experiment matrices: the Table 2 file, the case order, and rejection of bad input."""

import csv
import math
import re
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from eoam_sumo.errors import InputError
from eoam_sumo.matrix import DEFAULT_MAX_TIME_S, check_matrix, load_matrix, load_paper_table
from eoam_sumo.sim.scenario import ScenarioOverrides
from tests.builders import BASELINE

ROOT = Path(__file__).resolve().parents[1]
TABLE2 = ROOT / "scenarios" / "table2.toml"
PAPER_CSV = ROOT / "scenarios" / "paper_table2.csv"


def test_table2_has_the_papers_64_cases_in_the_papers_order():
    matrix = load_matrix(TABLE2)
    cases = matrix.cases()
    with PAPER_CSV.open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert len(cases) == len(rows) == 64
    for case, row in zip(cases, rows):
        onc = None if row["oncoming_start_m"] == "" else float(row["oncoming_start_m"])
        assert (case.oncoming_start_m, case.ego_speed_kmh, case.mu) == (
            onc,
            float(row["ego_speed_kmh"]),
            float(row["mu"]),
        )
        assert case.sumocfg == (ROOT / "scenarios" / "baseline.sumocfg").resolve()
        assert case.max_time_s == 60.0
    assert cases[0].case_id == "onc-none_v165_mu1.0"
    assert cases[-1].case_id == "onc-300_v55_mu0.1"
    assert len({c.case_id for c in cases}) == 64
    assert all(re.fullmatch(r"[A-Za-z0-9._-]+", c.case_id) for c in cases)


def test_paper_outcomes_match_the_published_table():
    matrix = load_matrix(TABLE2)
    outcomes = matrix.paper_outcomes()
    assert len(outcomes) == 64
    assert outcomes["onc-none_v165_mu0.1"] == "yellow"
    assert outcomes["onc-300_v165_mu0.7"] == "red"
    assert outcomes["onc-400_v120_mu0.7"] == "orange"
    assert load_paper_table(PAPER_CSV)[(None, 90.0, 0.1)] == "orange"


def test_case_overrides_convert_units():
    case = load_matrix(TABLE2).cases()[17]  # oncoming 500 m, 165 km/h, mu 0.7
    ov = case.overrides()
    assert isinstance(ov, ScenarioOverrides)
    assert ov.ego_speed_mps == pytest.approx(165.0 / 3.6, rel=1e-12)
    assert (ov.mu, ov.oncoming_start_m, ov.aro_hold_s, ov.aro_decel_mps2) == (
        0.7,
        500.0,
        None,
        None,
    )


def _write(tmp_path: Path, body: str, name: str = "m.toml") -> Path:
    (tmp_path / "s.sumocfg").write_text("<configuration/>")
    path = tmp_path / name
    path.write_text(body)
    return path


GOOD_SCENARIO = '[scenario]\nsumocfg = "s.sumocfg"\n'
GOOD_SWEEP = "[sweep]\nego_speed_kmh = [120]\nmu = [1.0]\n"


def test_optional_aro_keys_extend_the_sweep_and_the_ids(tmp_path):
    path = _write(
        tmp_path,
        GOOD_SCENARIO
        + GOOD_SWEEP
        + 'oncoming_start_m = [300, "none"]\naro_hold_s = [2.0, 0.5]\naro_decel_mps2 = [8.0]\n',
    )
    cases = load_matrix(path).cases()
    assert [c.case_id for c in cases] == [
        "onc-none_v120_mu1.0_hold2_dec8",
        "onc-none_v120_mu1.0_hold0.5_dec8",
        "onc-300_v120_mu1.0_hold2_dec8",
        "onc-300_v120_mu1.0_hold0.5_dec8",
    ]
    assert cases[1].overrides().aro_hold_s == 0.5
    assert cases[1].overrides().aro_decel_mps2 == 8.0
    assert cases[0].max_time_s == DEFAULT_MAX_TIME_S == 60.0  # documented default
    assert cases[0].radar_range_m is None  # the radar's own default


def test_scenario_radar_range_reaches_every_case(tmp_path):
    path = _write(tmp_path, GOOD_SCENARIO + "radar_range_m = 200\n" + GOOD_SWEEP)
    assert {c.radar_range_m for c in load_matrix(path).cases()} == {200.0}


BAD = [
    ("unknown table", GOOD_SCENARIO + GOOD_SWEEP + "[sweeps]\nmu = [1.0]\n", "sweeps", "sweep"),
    ("top-level key", "foo = 1\n" + GOOD_SCENARIO + GOOD_SWEEP, "foo", None),
    (
        "misspelt key",
        GOOD_SCENARIO + "[sweep]\nego_speed_kph = [120]\nmu = [1.0]\n",
        "ego_speed_kph",
        "ego_speed_kmh",
    ),
    (
        "misspelt scenario key",
        '[scenario]\nsumocfg = "s.sumocfg"\nmax_time = 3\n' + GOOD_SWEEP,
        "max_time",
        "max_time_s",
    ),
    ("not a list", GOOD_SCENARIO + "[sweep]\nego_speed_kmh = [120]\nmu = 1.0\n", "mu", None),
    ("string value", GOOD_SCENARIO + '[sweep]\nego_speed_kmh = [120]\nmu = ["dry"]\n', "mu", None),
    (
        "bool value",
        GOOD_SCENARIO + "[sweep]\nego_speed_kmh = [true]\nmu = [1.0]\n",
        "ego_speed_kmh",
        None,
    ),
    ("mu zero", GOOD_SCENARIO + "[sweep]\nego_speed_kmh = [120]\nmu = [0.0]\n", "mu", None),
    ("mu too high", GOOD_SCENARIO + "[sweep]\nego_speed_kmh = [120]\nmu = [1.5]\n", "mu", None),
    (
        "zero speed",
        GOOD_SCENARIO + "[sweep]\nego_speed_kmh = [0]\nmu = [1.0]\n",
        "ego_speed_kmh",
        None,
    ),
    (
        "negative speed",
        GOOD_SCENARIO + "[sweep]\nego_speed_kmh = [-90]\nmu = [1.0]\n",
        "ego_speed_kmh",
        None,
    ),
    (
        "negative distance",
        GOOD_SCENARIO + GOOD_SWEEP + "oncoming_start_m = [-5]\n",
        "oncoming_start_m",
        None,
    ),
    (
        "word distance",
        GOOD_SCENARIO + GOOD_SWEEP + 'oncoming_start_m = ["far"]\n',
        "oncoming_start_m",
        None,
    ),
    ("empty list", GOOD_SCENARIO + "[sweep]\nego_speed_kmh = [120]\nmu = []\n", "mu", None),
    (
        "duplicate",
        GOOD_SCENARIO + "[sweep]\nego_speed_kmh = [120, 120.0]\nmu = [1.0]\n",
        "ego_speed_kmh",
        None,
    ),
    (
        "duplicate none",
        GOOD_SCENARIO + GOOD_SWEEP + 'oncoming_start_m = ["none", "none"]\n',
        "oncoming_start_m",
        None,
    ),
    ("zero decel", GOOD_SCENARIO + GOOD_SWEEP + "aro_decel_mps2 = [0.0]\n", "aro_decel_mps2", None),
    (
        "missing sumocfg file",
        '[scenario]\nsumocfg = "nope.sumocfg"\n' + GOOD_SWEEP,
        "sumocfg",
        None,
    ),
    ("sumocfg not a string", "[scenario]\nsumocfg = 3\n" + GOOD_SWEEP, "sumocfg", None),
    ("no sumocfg key", "[scenario]\nmax_time_s = 10.0\n" + GOOD_SWEEP, "sumocfg", None),
    ("no speed key", GOOD_SCENARIO + "[sweep]\nmu = [1.0]\n", "ego_speed_kmh", None),
    ("no scenario table", GOOD_SWEEP, "scenario", None),
    (
        "bad max time",
        '[scenario]\nsumocfg = "s.sumocfg"\nmax_time_s = -1.0\n' + GOOD_SWEEP,
        "max_time_s",
        None,
    ),
    (
        "bad radar range",
        '[scenario]\nsumocfg = "s.sumocfg"\nradar_range_m = 0\n' + GOOD_SWEEP,
        "radar_range_m",
        None,
    ),
    (
        "missing paper table",
        GOOD_SCENARIO + GOOD_SWEEP + '[paper]\ntable = "none.csv"\n',
        "table",
        None,
    ),
    ("malformed toml", GOOD_SCENARIO + "[sweep\nmu = [1.0]\n", "TOML", None),
]


@pytest.mark.parametrize("body,key,suggestion", [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_matrix_is_rejected_naming_file_and_key(tmp_path, body, key, suggestion):
    path = _write(tmp_path, body)
    with pytest.raises(InputError) as err:
        load_matrix(path)
    message = str(err.value)
    assert str(path) in message
    assert key in message
    if suggestion is not None:
        assert f"did you mean '{suggestion}'" in message


def test_missing_matrix_file_is_an_input_error(tmp_path):
    with pytest.raises(InputError, match="not found"):
        load_matrix(tmp_path / "absent.toml")


def test_bad_paper_table_names_the_line(tmp_path):
    bad = tmp_path / "paper.csv"
    bad.write_text("oncoming_start_m,ego_speed_kmh,mu,outcome\n,165,1.0,green\n,120,1.0,purple\n")
    with pytest.raises(InputError, match="line 3"):
        load_paper_table(bad)
    bad.write_text("speed,mu,outcome\n165,1.0,green\n")
    with pytest.raises(InputError, match="oncoming_start_m"):
        load_paper_table(bad)


def _toml_number(x):
    return repr(x)


speeds = st.lists(
    st.one_of(st.integers(1, 300), st.floats(0.5, 300.0)), min_size=1, max_size=5, unique_by=float
)
mus = st.lists(st.floats(0.01, 1.2), min_size=1, max_size=4, unique=True)
distances = st.lists(
    st.one_of(st.just("none"), st.integers(0, 2000), st.floats(0.0, 2000.0)),
    min_size=1,
    max_size=4,
    unique_by=lambda d: d if isinstance(d, str) else float(d),
)


@settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(speeds=speeds, mus=mus, distances=distances)
def test_any_valid_sweep_gives_one_uniquely_named_case_per_combination(
    tmp_path, speeds, mus, distances
):
    def arr(values):
        return "[" + ", ".join('"none"' if v == "none" else _toml_number(v) for v in values) + "]"

    path = _write(
        tmp_path,
        GOOD_SCENARIO + f"[sweep]\nego_speed_kmh = {arr(speeds)}\n"
        f"mu = {arr(mus)}\noncoming_start_m = {arr(distances)}\n",
    )
    cases = load_matrix(path).cases()
    assert len(cases) == len(speeds) * len(mus) * len(distances)
    assert len({c.case_id for c in cases}) == len(cases)
    assert all(re.fullmatch(r"[A-Za-z0-9._-]+", c.case_id) for c in cases)
    # traffic outermost with "none" first, then speed, then friction, each in file order
    traffic = [None] * ("none" in distances) + [float(d) for d in distances if d != "none"]
    expected = [(d, float(v), float(m)) for d in traffic for v in speeds for m in mus]
    assert [(c.oncoming_start_m, c.ego_speed_kmh, c.mu) for c in cases] == expected
    assert all(math.isclose(c.overrides().ego_speed_mps * 3.6, c.ego_speed_kmh) for c in cases)


class _Tables:
    """The part of LookupTables that check_within_tables uses: 20-175 km/h, mu 0.1-1.0."""

    mu_grid = (0.1, 0.3, 0.7, 1.0)
    speed_grid_mps = (20 / 3.6, 175 / 3.6)

    def __init__(self):
        from eoam_sumo.offline.tables import LookupTables

        self.calls = []
        self._check = LookupTables.check_run

    def check_run(self, mu, speed_mps):
        self.calls.append((mu, speed_mps))
        self._check(self, mu, speed_mps)


@pytest.mark.parametrize(
    "sweep, message",
    [
        ("ego_speed_kmh = [120, 175]\nmu = [1.2, 0.1]\n", None),
        ("ego_speed_kmh = [120, 250]\nmu = [1.0]\n", "[sweep] ego_speed_kmh value 250 is outside"),
        ("ego_speed_kmh = [175.5]\nmu = [1.0]\n", "[sweep] ego_speed_kmh value 175.5 is outside"),
        ("ego_speed_kmh = [120]\nmu = [1.0, 0.05]\n", "[sweep] mu value 0.05 is outside"),
    ],
)
def test_every_swept_speed_and_friction_is_checked_against_the_tables(tmp_path, sweep, message):
    from eoam_sumo.matrix import check_within_tables

    matrix = load_matrix(_write(tmp_path, GOOD_SCENARIO + "[sweep]\n" + sweep))
    tables = _Tables()
    if message is None:
        check_within_tables(matrix, tables, "T")
        assert len(tables.calls) == len(matrix.ego_speeds_kmh) + len(matrix.mus)
        return
    with pytest.raises(InputError) as err:
        check_within_tables(matrix, tables, "T")
    assert str(err.value).startswith(f"{matrix.path}: {message} the lookup tables in T: ")


def test_check_matrix_uses_the_real_tables_and_scenario(monkeypatch):
    from eoam_sumo.matrix import check_matrix

    monkeypatch.delenv("EOAM_TABLES_DIR", raising=False)
    check_matrix(load_matrix(TABLE2))  # the paper's matrix is within the repository's tables


def test_check_matrix_parses_the_scenario(tmp_path):
    from eoam_sumo.matrix import check_matrix

    path = _write(tmp_path, GOOD_SCENARIO + GOOD_SWEEP)  # s.sumocfg has no net-file
    with pytest.raises(InputError, match=r"m\.toml: \[scenario\] sumocfg: .*s\.sumocfg.*net-file"):
        check_matrix(load_matrix(path))


def test_check_matrix_refuses_a_stop_profile_for_a_scenario_without_an_aro(tmp_path):
    from eoam_sumo.matrix import check_matrix

    cfg = ROOT / "scenarios" / "parked_only.sumocfg"  # the ego and parked cars: no ARO
    path = tmp_path / "m.toml"
    path.write_text(
        f'[scenario]\nsumocfg = "{cfg.as_posix()}"\n'
        "[sweep]\nego_speed_kmh = [120]\nmu = [1.0]\naro_hold_s = [1.0]\n"
    )
    with pytest.raises(InputError, match=r"m\.toml: \[scenario\] sumocfg: .*eoam.role"):
        check_matrix(load_matrix(path))


def test_speeds_below_the_design_range_are_refused():
    tables = _Tables()
    with pytest.raises(InputError, match=r"4.0 km/h is outside the design range \[5, 175\]"):
        tables.check_run(1.0, 4.0 / 3.6)
    tables.check_run(1.0, 5.0 / 3.6)  # the design range's floor (below the grid: braking only)
    tables.check_run(1.0, 15.0 / 3.6)


def test_a_matrix_sampling_every_swept_key_needs_no_sweep_table(tmp_path):
    """docs/monte-carlo.md: a sampled key leaves the sweep; when every required one is sampled,
    [sweep] may be left out (as it may be left empty), and is still checked when given."""
    sample = (
        "[sample]\ndraws = 2\nseed = 1\nego_speed_kmh = { uniform = [60, 140] }\n"
        "mu = { choice = [0.3, 0.7] }\n"
    )
    scenario = f'[scenario]\nsumocfg = "{(ROOT / "scenarios" / "baseline.sumocfg").as_posix()}"\n'
    without = tmp_path / "without.toml"
    without.write_text(scenario + sample)
    empty = tmp_path / "empty.toml"
    empty.write_text(scenario + "[sweep]\n" + sample)
    ids = [c.case_id for c in load_matrix(without).cases()]
    assert ids == [c.case_id for c in load_matrix(empty).cases()]
    assert len(ids) == 2
    # only sampling every required key leaves it out
    half = tmp_path / "half.toml"
    half.write_text(scenario + sample.replace("ego_speed_kmh = { uniform = [60, 140] }\n", ""))
    with pytest.raises(InputError, match=r"half\.toml: missing table \[sweep\]"):
        load_matrix(half)


def test_sumo_step_is_a_scenario_key_checked_and_carried_by_every_case(tmp_path):
    path = _write(tmp_path, GOOD_SCENARIO + "sumo_step_s = 0.05\n" + GOOD_SWEEP)
    cases = load_matrix(path).cases()
    assert [c.sumo_step_s for c in cases] == [0.05]
    assert load_matrix(_write(tmp_path, GOOD_SCENARIO + GOOD_SWEEP)).cases()[0].sumo_step_s is None
    for bad in ("0.015", "0.2", "0", '"fast"'):
        path = _write(tmp_path, GOOD_SCENARIO + f"sumo_step_s = {bad}\n" + GOOD_SWEEP)
        with pytest.raises(InputError, match=r"m\.toml: \[scenario\] sumo_step_s"):
            load_matrix(path)


ONE_WAY_NET = (
    '<net version="1.20"><edge id="E0" from="w" to="e">'
    '<lane id="E0_0" index="0" speed="50" length="3000" shape="0,-5.25 3000,-5.25"/>'
    '<lane id="E0_1" index="1" speed="50" length="3000" shape="0,-1.75 3000,-1.75"/>'
    "</edge></net>"
)
EGO_ROUTES = {
    "named": '<routes><route id="r" edges="E0"/><vehicle id="ego" route="r" depart="1"/></routes>',
    "embedded": '<routes><vehicle id="ego" depart="1"><route edges="E0"/></vehicle></routes>',
}


@pytest.mark.parametrize("route", sorted(EGO_ROUTES))
def test_an_oncoming_start_on_a_one_way_road_is_refused_before_any_case(tmp_path, route):
    """``batch`` checks the scenario's road for what the matrix asks before any case runs:
    an oncoming car on a road without a lane of the other direction is bad input."""
    from eoam_sumo.batch.runner import plan_batch

    (tmp_path / "n.net.xml").write_text(ONE_WAY_NET)
    (tmp_path / "r.rou.xml").write_text(EGO_ROUTES[route])
    cfg = tmp_path / "s.sumocfg"
    cfg.write_text(
        '<configuration><input><net-file value="n.net.xml"/>'
        '<route-files value="r.rou.xml"/></input></configuration>'
    )
    sweep = 'ego_speed_kmh = [120]\nmu = [1.0]\noncoming_start_m = ["none", 300]\n'
    path = tmp_path / "m.toml"
    path.write_text(f'[scenario]\nsumocfg = "s.sumocfg"\n[sweep]\n{sweep}')
    with pytest.raises(InputError, match=r"m\.toml: oncoming_start_m = 300: .*n\.net\.xml: "):
        plan_batch(path)
    path.write_text(f'[scenario]\nsumocfg = "s.sumocfg"\n[sweep]\n{sweep.replace(", 300", "")}')
    assert len(plan_batch(path).cases) == 1  # no oncoming car asked: the road is fine


def test_a_sampled_v2x_range_needs_the_safe_policy(tmp_path):
    """Refused before any case runs, as the same value in [scenario] is (every case failed at
    run time, exit 1)."""
    path = tmp_path / "m.toml"
    path.write_text(
        f'[scenario]\nsumocfg = "{BASELINE}"\n[sweep]\nego_speed_kmh = [120]\nmu = [0.7]\n'
        "[sample]\ndraws = 2\nv2x_range_m = { uniform = [0, 300] }\n",
        encoding="utf-8",
    )
    with pytest.raises(InputError, match=r"\[sample\] v2x_range_m: V2X informs the safe policy"):
        load_matrix(path)


def test_an_oncoming_start_on_a_generated_motorway_is_refused_up_front(tmp_path):
    """A generated motorway's carriageways are apart: every case failed at run time."""
    path = tmp_path / "m.toml"
    path.write_text(
        '[scenario]\nroad = "motorway"\nlos = "A"\n'
        "[sweep]\nego_speed_kmh = [100]\nmu = [0.7]\noncoming_start_m = [300]\n",
        encoding="utf-8",
    )
    with pytest.raises(InputError, match="oncoming_start_m = 300 on a generated motorway"):
        check_matrix(load_matrix(path))


def test_a_folder_given_as_the_scenario_is_called_a_folder(tmp_path):
    path = tmp_path / "m.toml"
    path.write_text(
        f'[scenario]\nsumocfg = "{tmp_path}"\n[sweep]\nego_speed_kmh = [120]\nmu = [0.7]\n',
        encoding="utf-8",
    )
    with pytest.raises(InputError, match="is a folder, not a file"):
        load_matrix(path)
