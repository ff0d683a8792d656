"""The fixed parts of the EOAM controller: built once, from the settings, at construction."""

from __future__ import annotations

from typing import Any, NamedTuple

from eoam_sumo.control.longitudinal import LongitudinalController
from eoam_sumo.control.steering import SteeringController
from eoam_sumo.decision.policy import SafePolicy
from eoam_sumo.eoam.strategies import (
    ArrestFirst,
    BrakingObstaclePlacement,
    CompareOutcomes,
    LateralStopPonr,
    MinTimeEscapes,
    NextLaneGate,
    OffsetPonr,
    PaperPlacement,
    PonrCommit,
    QuinticEscapes,
    SafeGate,
    StableReturn,
    TimerReturn,
)
from eoam_sumo.eoam_settings import EoamSettings
from eoam_sumo.params import VehicleParams


class Parts(NamedTuple):
    """What the step uses but does not change: vehicle, tables, settings, the controllers
    (which reset their own integrators) and the rules chosen from the settings."""

    params: VehicleParams
    tables: Any  # offline.tables.LookupTables
    settings: EoamSettings
    steering: SteeringController  # lane keeping and the shifts
    planned_steering: SteeringController  # the table lane change, with its planned steering
    longitudinal: LongitudinalController
    placement: PaperPlacement  # where the DMM places the obstacle
    commit: PonrCommit  # pass on or abort when oncoming traffic appears in mode 2
    escapes: QuinticEscapes  # the shifts of modes 3, 4 and the urgent return
    return_rule: TimerReturn  # when mode 2 returns
    gate: NextLaneGate  # the decision policy's checks of the next lane
    side_judge: SafePolicy  # the checks of a lane on either side (``sides.open_side``)


def build_parts(params: VehicleParams, tables: Any, settings: EoamSettings) -> Parts:
    """The controllers, and each rule as the settings choose it (``strategies``)."""
    st = settings
    ponr = LateralStopPonr(st) if st.ponr_at_lateral_stop else OffsetPonr(st)
    escapes: QuinticEscapes
    if not st.min_time_escapes:
        escapes = QuinticEscapes(st)
    elif st.arrest_first:
        escapes = ArrestFirst(st)
    else:
        escapes = MinTimeEscapes(st)
    steering = SteeringController(params, st.steering, st.preview_time_s)
    return Parts(
        params,
        tables,
        st,
        steering,
        SteeringController(params, st.planned_steering),
        LongitudinalController(params, st.longitudinal),
        BrakingObstaclePlacement() if st.obstacle_decel_in_dmm else PaperPlacement(),
        CompareOutcomes(params, st, ponr) if st.compare_outcomes else PonrCommit(params, st, ponr),
        escapes,
        StableReturn(st, steering) if st.return_when_stable else TimerReturn(st),
        SafeGate(SafePolicy(params, tables, st, st.policy))
        if st.policy.name == "safe"
        else NextLaneGate(
            SafePolicy(params, tables, st, st.policy) if st.policy.check_target_lane else None
        ),
        SafePolicy(params, tables, st, st.policy),
    )
