"""eoam-sumo: the EOAM framework of Lowe & Guvenc (2022) co-simulated with Eclipse SUMO."""

__version__ = "0.1.0"
