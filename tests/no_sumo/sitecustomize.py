"""SUMO made unreachable for the fast test tier (``make test-fast`` puts this folder first on
PYTHONPATH, so every Python process of the run, subprocesses included, loads it).

Importing libsumo, traci or sumo (the package that carries SUMO's binaries) fails, and so does
starting a sumo, sumo-gui or netconvert process: a test that needs SUMO without its ``sumo``
marker fails in that tier instead of passing slowly."""

import os
import subprocess
import sys

_MODULES = frozenset({"libsumo", "traci", "sumo"})
_PROGRAMS = frozenset({"sumo", "sumo-gui", "netconvert", "sumoD", "netconvertD"})


class _NoSumoFinder:
    @staticmethod
    def find_spec(name, path=None, target=None):
        if name.partition(".")[0] in _MODULES:
            raise ImportError(
                f"{name}: SUMO is unreachable in the fast test tier "
                "(mark the test with @pytest.mark.sumo)"
            )


class _NoSumoPopen(subprocess.Popen):
    def __init__(self, args, *rest, **kwargs):
        program = os.fsdecode(args if isinstance(args, (str, bytes, os.PathLike)) else args[0])
        if os.path.basename(program.split()[0] if isinstance(args, str) else program) in _PROGRAMS:
            raise FileNotFoundError(
                f"{program}: SUMO is unreachable in the fast test tier "
                "(mark the test with @pytest.mark.sumo)"
            )
        super().__init__(args, *rest, **kwargs)


sys.meta_path.insert(0, _NoSumoFinder())
subprocess.Popen = _NoSumoPopen
