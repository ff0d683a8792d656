"""The generated scenario's keys in an experiment matrix (no SUMO)."""

from __future__ import annotations

import pytest

from eoam_sumo.errors import InputError
from eoam_sumo.matrix import GENERATED, load_matrix


def _matrix(tmp_path, text: str):
    path = tmp_path / "m.toml"
    path.write_text(text)
    return load_matrix(path)


def test_roads_and_levels_are_swept_before_speed_and_friction(tmp_path):
    m = _matrix(
        tmp_path,
        """
[scenario]
lanes = 3
[sweep]
road = ["motorway"]
los = ["A", "E"]
ego_speed_kmh = [100]
mu = [1.0, 0.5]
""",
    )
    cases = m.cases()
    assert [c.case_id for c in cases] == [
        "motorway_losA_l3_onc-none_v100_mu1.0",
        "motorway_losA_l3_onc-none_v100_mu0.5",
        "motorway_losE_l3_onc-none_v100_mu1.0",
        "motorway_losE_l3_onc-none_v100_mu0.5",
    ]
    assert all(c.sumocfg == GENERATED for c in cases)
    spec = cases[2].traffic()
    assert (spec.road, spec.los, spec.lanes, spec.curve_radius_m) == ("motorway", "E", 3, None)


def test_sampled_roads_and_curves(tmp_path):
    m = _matrix(
        tmp_path,
        """
[scenario]
road = "rural"
[sweep]
curve_radius_m = ["none", 400]
[sample]
draws = 2
seed = 1
los = { choice = ["A", "C", "E"] }
ego_speed_kmh = { uniform = [60, 120] }
mu = { uniform = [0.3, 1.0] }
""",
    )
    cases = m.cases()
    assert [c.case_id for c in cases] == [
        "rural_straight_onc-none_d0",
        "rural_straight_onc-none_d1",
        "rural_R400_onc-none_d0",
        "rural_R400_onc-none_d1",
    ]
    assert {c.los for c in cases} <= {"A", "C", "E"}
    assert cases[0].curve_radius_m is None and cases[2].curve_radius_m == 400.0
    assert cases[0].traffic().seed == cases[0].seed


@pytest.mark.parametrize(
    "text, message",
    [
        (
            '[scenario]\nroad = "city"\nlos = "A"\n[sweep]\nego_speed_kmh=[90]\nmu=[1.0]',
            "road 'city'",
        ),
        (
            '[scenario]\nroad = "motorway"\nlos = "A"\ncurve_radius_m = 400\n'
            "[sweep]\nego_speed_kmh=[90]\nmu=[1.0]",
            "rural road only",
        ),
        ('[scenario]\nlos = "A"\n[sweep]\nego_speed_kmh=[90]\nmu=[1.0]', "needs the key 'road'"),
        ("[sweep]\nego_speed_kmh=[90]\nmu=[1.0]", "needs the key 'sumocfg'"),
        (
            '[scenario]\nroad = "rural"\n[sweep]\nego_speed_kmh=[90]\nmu=[1.0]',
            "needs the key 'los'",
        ),
        (
            '[scenario]\nroad = "rural"\n[sweep]\nlos = ["G"]\nego_speed_kmh=[90]\nmu=[1.0]',
            "level of service 'G'",
        ),
        (
            '[scenario]\nroad = "rural"\nlos = "A"\nafter_stop_s = -1\n'
            "[sweep]\nego_speed_kmh=[90]\nmu=[1.0]",
            "after_stop_s",
        ),
    ],
)
def test_bad_keys_are_named_with_the_file(tmp_path, text, message):
    with pytest.raises(InputError, match=message) as err:
        _matrix(tmp_path, text)
    assert "m.toml" in str(err.value)
