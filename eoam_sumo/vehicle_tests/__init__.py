"""The standard vehicle tests: sine with dwell (FMVSS 126 / UN R140), straight-line braking
(UN R13-H / FMVSS 135), the brake lock order (UN R13-H Annex 5), ramp steer (ISO 4138) and
step steer (ISO 7401), each a pure function ``(params, options) -> VehicleTestResult`` driving the
plant (``harness.py``), listed in ``procedures.TESTS``; ``command.py`` is
``eoam-sumo vehicle-test``. No SUMO, pandas or matplotlib here but the command's figure
(``eoam_sumo.plotting.vehicle_tests``)."""
