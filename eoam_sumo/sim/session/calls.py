"""The SUMO functions the co-simulation step calls, bound once a session: :class:`StepCalls`.

libsumo's Python layer wraps each function of its C binding in a static method that passes
the arguments on (``libsumo.vehicle.getAngle(v)`` returns ``_libsumo.vehicle_getAngle(v)``),
and ``simulationStep`` in the step listeners of ``libsumo.addStepListener`` (eoam-sumo adds
none). Through libsumo the step calls the binding's functions themselves, one Python frame
less for each of the step's SUMO calls. A function this libsumo lacks, and every function
through TraCI (sumo-gui, ``use_traci``), is the client's own method.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any


def _native(api) -> Any:
    """libsumo's C binding (``libsumo._libsumo``), or None through TraCI."""
    if not getattr(api, "isLibsumo", lambda: False)():
        return None
    return getattr(api, "_libsumo", None)


class StepCalls:
    """The step's SUMO functions, each the binding's own where libsumo has it."""

    def __init__(self, api) -> None:
        native = _native(api)

        def bind(domain: str, name: str) -> Callable[..., Any]:
            direct = getattr(native, f"{domain}_{name}", None) if native is not None else None
            return direct if direct is not None else getattr(getattr(api, domain), name)

        #: one SUMO step, called with 0.0 (libsumo's ``simulation_step`` is its
        #: ``simulationStep`` less the step listeners)
        self.step: Callable[..., Any] = (
            getattr(native, "simulation_step", None) or api.simulationStep
        )
        self.time: Callable[..., Any] = bind("simulation", "getTime")
        self.departed_ids: Callable[..., Any] = bind("simulation", "getDepartedIDList")
        self.departed_person_ids: Callable[..., Any] = bind("simulation", "getDepartedPersonIDList")
        self.arrived_person_ids: Callable[..., Any] = bind("simulation", "getArrivedPersonIDList")
        self.move_to_xy: Callable[..., Any] = bind("vehicle", "moveToXY")
        self.set_speed: Callable[..., Any] = bind("vehicle", "setSpeed")
        self.angle: Callable[..., Any] = bind("vehicle", "getAngle")
        self.speed: Callable[..., Any] = bind("vehicle", "getSpeed")
        self.stop_state: Callable[..., Any] = bind("vehicle", "getStopState")
        self.type_id: Callable[..., Any] = bind("vehicle", "getTypeID")
        self.vehicle_results: Callable[..., Any] = bind("vehicle", "getAllSubscriptionResults")
        self.context_results: Callable[..., Any] = bind("vehicle", "getContextSubscriptionResults")
        self.person_results: Callable[..., Any] = bind("person", "getAllSubscriptionResults")
