"""Manoeuvre geometry, beneath decision and control: the quintic (paper sec. 4.2) and the
time-optimal lateral shifts, the points of a trajectory and of a sampled reference, the
reference sampled from the tables at the trigger, the ego's lateral state relative to the
road and angle wrapping. Imports only the standard library and numpy."""

from eoam_sumo.manoeuvre.angles import wrap_angle
from eoam_sumo.manoeuvre.lateral_state import course_state, lateral_state
from eoam_sumo.manoeuvre.min_time_shift import MinTimeShift
from eoam_sumo.manoeuvre.path_reference import PathReference
from eoam_sumo.manoeuvre.points import PathPoint, TrajectoryPoint
from eoam_sumo.manoeuvre.quintic_shift import QuinticShift

__all__ = [
    "MinTimeShift",
    "PathPoint",
    "PathReference",
    "QuinticShift",
    "TrajectoryPoint",
    "course_state",
    "lateral_state",
    "wrap_angle",
]
