"""Generated traffic scenarios: a rural two-lane road or a motorway, traffic at a level of
service of the Highway Capacity Manual (``hcm.py``), an obstacle and the ego placed in a gap
of the traffic (``build.py``); ``eoam-sumo scenario`` (``command.py``) and the matrix keys
``road``, ``los``, ``lanes``, ``speed_limit_kmh``, ``curve_radius_m`` (``spec.py``)."""
