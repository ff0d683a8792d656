"""Re-exports of the lateral-escape geometry, now in ``eoam_sumo.manoeuvre``."""

# re-exported for eoam.py until the merge
from eoam_sumo.manoeuvre.angles import wrap_angle
from eoam_sumo.manoeuvre.lateral_state import course_state, lateral_state
from eoam_sumo.manoeuvre.min_time_shift import MinTimeShift

__all__ = ["MinTimeShift", "course_state", "lateral_state", "wrap_angle"]
