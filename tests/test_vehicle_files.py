"""Vehicle files: a VehicleParams round-trips through TOML; a bad file names its key."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import pytest

from eoam_sumo.errors import InputError
from eoam_sumo.params import VehicleParams, ego_e_class_sedan
from eoam_sumo.vehicle_files import (
    CATALOGUE_HEADER,
    catalogue,
    catalogue_row,
    load_vehicle,
    sources_of,
    vehicle_path,
    vehicle_toml,
)


def _write(tmp_path, text: str, name: str = "car.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_the_sedan_round_trips_through_its_file(tmp_path):
    sedan = ego_e_class_sedan()
    path = _write(tmp_path, vehicle_toml(sedan))
    assert load_vehicle(str(path)) == sedan


def test_a_changed_value_is_read_back(tmp_path):
    heavier = dataclasses.replace(ego_e_class_sedan(), mass_kg=2100.0, name="heavy")
    assert load_vehicle(str(_write(tmp_path, vehicle_toml(heavier)))) == heavier


def test_a_file_edited_in_place_is_read_again(tmp_path):
    """A process keeps what it read of a file, but not past an edit of the same length made
    within the file system's time resolution."""
    sedan = ego_e_class_sedan()
    path = _write(tmp_path, vehicle_toml(sedan))
    assert load_vehicle(str(path)) is load_vehicle(str(path))
    edited = dataclasses.replace(sedan, mass_kg=sedan.mass_kg + 1.0)
    text = vehicle_toml(edited)
    assert len(text) == len(vehicle_toml(sedan))
    path.write_text(text)
    assert load_vehicle(str(path)) == edited
    path.write_text("[mass_kg\n")
    with pytest.raises(InputError, match="not valid TOML"):
        load_vehicle(str(path))


def _without_table(text: str, key: str) -> str:
    return re.sub(rf"\[{key}\]\n(.*\n){{3}}", "", text)


@pytest.mark.parametrize("key", ["mass_kg", "yaw_inertia_kgm2", "name"])
def test_a_missing_key_is_named(tmp_path, key):
    text = _without_table(vehicle_toml(ego_e_class_sedan()), key)
    with pytest.raises(InputError, match=rf"car.toml: key '{key}' is missing"):
        load_vehicle(str(_write(tmp_path, text)))


def test_a_negative_value_is_named(tmp_path):
    text = vehicle_toml(ego_e_class_sedan()).replace("value = 1723.0", "value = -1723.0")
    with pytest.raises(
        InputError,
        match=r"car\.toml: key 'mass_kg' = -1723.0 kg is outside its physical range "
        r"\[200, 60000\] kg",
    ):
        load_vehicle(str(_write(tmp_path, text)))


def test_a_wrong_unit_an_unknown_key_and_a_missing_source_are_named(tmp_path):
    text = vehicle_toml(ego_e_class_sedan())
    cases = {
        'unit = "kg"': ('unit = "lb"', "key 'mass_kg' has unit 'lb', not 'kg'"),
        "[mass_kg]": ("[mass_kgs]", "unknown key 'mass_kgs'"),
    }
    for old, (new, message) in cases.items():
        with pytest.raises(InputError, match=re.escape(message)):
            load_vehicle(str(_write(tmp_path, text.replace(old, new, 1))))
    no_source = re.sub(r'(\[mass_kg\]\n.*\n.*\n)source = ".*"', r'\1source = ""', text)
    with pytest.raises(InputError, match="key 'mass_kg' has no source"):
        load_vehicle(str(_write(tmp_path, no_source)))


def test_a_value_of_the_wrong_type_is_named(tmp_path):
    text = vehicle_toml(ego_e_class_sedan()).replace("value = 1723.0", 'value = "heavy"')
    with pytest.raises(InputError, match="key 'mass_kg' = 'heavy' must be a float"):
        load_vehicle(str(_write(tmp_path, text)))


def test_an_integer_too_large_for_a_float_is_named(tmp_path):
    text = vehicle_toml(ego_e_class_sedan()).replace("value = 1723.0", "value = 1" + "0" * 400)
    with pytest.raises(InputError, match=r"key 'mass_kg' = 10+ is too large for a float"):
        load_vehicle(str(_write(tmp_path, text)))


def test_broken_toml_and_unknown_names_are_one_line_errors(tmp_path):
    with pytest.raises(InputError, match=r"car\.toml: not valid TOML"):
        load_vehicle(str(_write(tmp_path, "[mass_kg\n")))
    with pytest.raises(InputError, match=r"--vehicle 'hovercraft': not in the catalogue \(a\)"):
        (tmp_path / "fleet").mkdir()
        _write(tmp_path / "fleet", vehicle_toml(ego_e_class_sedan()), "a.toml")
        vehicle_path("hovercraft", tmp_path / "fleet")
    with pytest.raises(InputError, match="no such vehicle file"):
        vehicle_path(str(tmp_path / "missing.toml"))


def test_a_catalogue_name_finds_its_file(tmp_path):
    _write(tmp_path, vehicle_toml(ego_e_class_sedan()), "sedan.toml")
    assert catalogue(tmp_path) == ["sedan"]
    assert load_vehicle("sedan", tmp_path) == VehicleParams()


def test_the_shipped_sedan_is_the_papers_car():
    assert {"sedan", "sedan-r13h"} <= set(catalogue())
    assert load_vehicle("sedan") == ego_e_class_sedan()


def test_a_vehicles_own_sources_and_a_header_are_written_and_read_back(tmp_path):
    compact = load_vehicle("compact")
    sources = sources_of("compact")
    text = vehicle_toml(compact, sources, header="A compact car.\nSecond line.")
    assert text.startswith("# A compact car.\n# Second line.\n\n[name]")
    path = _write(tmp_path, text)
    assert load_vehicle(str(path)) == compact
    assert sources_of(str(path)) == sources


def test_every_catalogue_file_is_the_canonical_writing_of_its_values():
    """Each shipped file, header comments aside, is what ``vehicle_toml`` writes for its
    values and sources: no stray table, every value in the dataclass's type."""
    for name in catalogue():
        text = vehicle_path(name).read_text()
        body = text[text.index("[name]") :]
        assert vehicle_toml(load_vehicle(name), sources_of(name)) == body, name


def test_sources_for_unknown_keys_are_refused():
    with pytest.raises(ValueError, match="mass_kgs"):
        vehicle_toml(ego_e_class_sedan(), {"mass_kgs": "typo"})


def test_the_catalogue_table_in_the_docs_is_the_files():
    """docs/vehicles.md's table of the vehicles holds each catalogue file's values, as
    ``catalogue_row`` writes them from the file (a hand-typed row went stale before)."""
    doc = (Path(__file__).resolve().parents[1] / "docs" / "vehicles.md").read_text("utf-8")
    assert CATALOGUE_HEADER in doc
    for name in catalogue():
        assert catalogue_row(name) in doc.splitlines(), name
