"""UN R157 (ALKS) Annex 4 Appendix 3 studies (``eoam-sumo r157-study``): cut-in, cut-out and
deceleration scenarios generated as SUMO files (``scenario.py``), run for the EOAM and the
reference drivers (``study.py``), charted as the regulation's figures (``plotting``)."""
