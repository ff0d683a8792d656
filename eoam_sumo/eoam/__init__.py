"""The online EOAM module: one decision + control step per SUMO step (paper sec. 3, 5-6, 8-9).

Every step the controller places the sensed obstacle in the DMM phase diagram (sectors A-G),
advances the mode machine 0-5 (point of no return, manoeuvre timer, return, hand-back), builds
the lateral and longitudinal references of the active mode and runs the steering (eq. 38) and
longitudinal controllers. It sees only ego measurements and radar-derived perception.

References per mode (road frame of the ego's original lane, d left positive):

* 0 NORMAL, 1 UPDATE BRAKE: keep the lane centre; 0 holds the initial speed (speed PID), 1
  brakes at the no-lock limit to standstill unless a steering sector, oncoming traffic or the
  obstacle leaving the path (or pulling away) ends it.
* 2 STEER+BRAKE: the table lane change (trigger speed and friction) to one lane width left,
  steered with the plan's own road-wheel angle; the table acceleration profile, then held.
* 3 ONCOMING BRAKE: a lateral motion away from the lane centre arrested at the front tyre's
  slip envelope, then back to the lane centre (a time-optimal ``MinTimeShift`` within
  ``arrest_return_g`` mu g, ``evasive_lateral_g`` without an arrest; or a quintic), braking
  with what the friction ellipse leaves meanwhile, then at the limit to standstill.
* 4 ONCOMING STEER+BRAKE: the same kind of shift to just past the obstacle's side.
* 5 RETURN: back to d = 0: a quintic within ``return_lateral_g`` mu g, an escape after mode 4.

When an oncoming road user is seen during a lane change, passing on and aborting are both
predicted and the less severe taken (``compare_outcomes``; ``decision.oncoming``); otherwise the
point of no return (sec. 8.1) is judged where the lateral motion would stop
(``ponr_at_lateral_stop``). The DMM places a braking obstacle where it will stop
(``obstacle_decel_in_dmm``). Each can be set back to the paper's rule.

The step's stages, one module each: ``perceive`` (measurement, friction, obstacle track,
coasted object, oncoming traffic), ``decide`` (DMM sector and action, the next lane's gate),
``transitions`` (mode machine, entry actions), ``lateral`` and ``longitudinal`` (control), over
one mutable ``state.ControllerState``; the fixed ``parts`` hold the controllers and the rules
chosen from the settings (``strategies``: the paper's or ours).
"""

from eoam_sumo.eoam.controller import EoamController
from eoam_sumo.eoam_messages import Command, EgoMeasurement, ObjectState, Perception
from eoam_sumo.eoam_settings import EoamSettings

__all__ = [
    "Command",
    "EgoMeasurement",
    "EoamController",
    "EoamSettings",
    "ObjectState",
    "Perception",
]
