"""Scripted emergency stops (paper sec. 10.1, Figure 19) as the scenario files give them.

A vehicle with the ``<param>`` ``eoam.aro_hold_s`` and ``eoam.aro_decel_mps2`` keeps its
departure speed for ``aro_hold_s`` after departing, then decelerates at
``min(aro_decel_mps2, mu_lane * g)`` to standstill and stays there, mu_lane being the friction
of the lane under it (the session carries the stop out). ``eoam.role=aro`` tags the vehicles
whose stop the run's overrides replace.
"""

from __future__ import annotations

from eoam_sumo.errors import InputError
from eoam_sumo.sim.scenario.files import ScenarioFiles, float_attr
from eoam_sumo.sim.scenario.overrides import ScenarioOverrides
from eoam_sumo.sim.scenario.values import number

ROLE_KEY = "eoam.role"
HOLD_KEY = "eoam.aro_hold_s"
DECEL_KEY = "eoam.aro_decel_mps2"


def scripted_stops(
    files: ScenarioFiles, overrides: ScenarioOverrides, ego_id: str | None = None
) -> dict:
    """Vehicle id -> (hold_s, decel_mps2) for every vehicle whose stop is scripted (not the
    ego's: the plant drives it, whatever its parameters say)."""
    stops, aro_seen = {}, False
    for spec in files.vehicles.values():
        if spec.vid == ego_id:
            continue
        is_aro = spec.params.get(ROLE_KEY) == "aro"
        aro_seen = aro_seen or is_aro
        values = {}
        for key, override in (
            (HOLD_KEY, overrides.aro_hold_s),
            (DECEL_KEY, overrides.aro_decel_mps2),
        ):
            if is_aro and override is not None:
                values[key] = override
            elif key in spec.params:
                values[key] = float_attr(spec, f"param {key}", spec.params[key])
        if not values:
            continue
        missing = [k for k in (HOLD_KEY, DECEL_KEY) if k not in values]
        if missing:
            raise InputError(
                f"{spec.source}: vehicle '{spec.vid}' has a scripted stop but no "
                f'<param key="{missing[0]}">'
            )
        hold = number(
            f"{spec.source}: vehicle '{spec.vid}' {HOLD_KEY}", values[HOLD_KEY], minimum=0.0
        )
        decel = number(
            f"{spec.source}: vehicle '{spec.vid}' {DECEL_KEY}",
            values[DECEL_KEY],
            minimum=0.0,
            inclusive=False,
        )
        stops[spec.vid] = (hold, decel)
    if not aro_seen and (overrides.aro_hold_s is not None or overrides.aro_decel_mps2 is not None):
        raise InputError(
            f"{files.cfg}: aro_hold_s/aro_decel_mps2 given but no vehicle has "
            f'<param key="{ROLE_KEY}" value="aro">'
        )
    return stops
