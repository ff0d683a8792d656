"""Shared plant fixtures: ONE compiled plant per test session, built under a temporary dir."""

import pytest

from eoam_sumo.params import ego_e_class_sedan
from eoam_sumo.plant import Plant


@pytest.fixture(scope="session")
def params():
    return ego_e_class_sedan()


@pytest.fixture(scope="session")
def plant_cache_dir(tmp_path_factory):
    return tmp_path_factory.mktemp("plant_cache")


@pytest.fixture(scope="session")
def plant(params, plant_cache_dir):
    compiled = Plant(params, dt_s=1e-3, substeps=10, cache_dir=plant_cache_dir)
    assert compiled.backend == "compiled-c"
    return compiled
