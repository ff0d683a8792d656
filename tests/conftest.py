"""Suite-wide fixtures: keep every file the tests make under pytest's temporary folders."""

from __future__ import annotations

import os
import shutil
import tempfile

import pytest
from hypothesis import settings
from hypothesis.configuration import set_hypothesis_home_dir

# No example database (it would be written into the working tree) and the same examples on
# every run: a property test that fails, fails again on the next run and on CI.
settings.register_profile("eoam", database=None, derandomize=True)
settings.load_profile("eoam")
# Hypothesis's own cache (constants of the code under test, kept from collection on) in a
# temporary folder removed at the end, not ``.hypothesis/`` in the working tree.
_HYPOTHESIS_HOME = tempfile.mkdtemp(prefix="eoam-hypothesis-")
set_hypothesis_home_dir(_HYPOTHESIS_HOME)


def pytest_unconfigure(config):
    shutil.rmtree(_HYPOTHESIS_HOME, ignore_errors=True)


@pytest.fixture(scope="session", autouse=True)
def _plant_cache_in_tmp(tmp_path_factory):
    """The compiled plant library goes to a temporary cache (inherited by subprocesses)."""
    old = os.environ.get("EOAM_SUMO_CACHE_DIR")
    os.environ["EOAM_SUMO_CACHE_DIR"] = str(tmp_path_factory.mktemp("plant-cache"))
    yield
    if old is None:
        os.environ.pop("EOAM_SUMO_CACHE_DIR", None)
    else:
        os.environ["EOAM_SUMO_CACHE_DIR"] = old
