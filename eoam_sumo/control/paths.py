"""Re-exports of the manoeuvre paths, now in ``eoam_sumo.manoeuvre``."""

# re-exported for eoam.py until the merge
from eoam_sumo.manoeuvre.path_reference import PathReference
from eoam_sumo.manoeuvre.quintic_shift import QuinticShift

__all__ = ["PathReference", "QuinticShift"]
