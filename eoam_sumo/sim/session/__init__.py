"""A running SUMO (libsumo in-process, TraCI for the GUI) with the ego under external control.

Modules: ``session`` (:class:`SumoSession`: start, stepping, queries, close), ``launch``
(command line, SUMO's options and error messages), ``insertion`` (the ego and the oncoming
car), ``tracking`` (every road user, through subscriptions), ``scripts`` (scripted stops).
"""

from eoam_sumo.sim.session.session import SumoSession

__all__ = ["SumoSession"]
