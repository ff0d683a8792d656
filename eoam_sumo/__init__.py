"""eoam-sumo: the EOAM framework of Lowe & Guvenc (2022) co-simulated with Eclipse SUMO."""

from eoam_sumo.native import choose as _choose

__version__ = "0.1.0"
_choose()  # the compiled modules, or the sources when they changed since the build
