"""Reference drivers as the ego's controller (``--driver``): the UN R157 competent and careful
human driver (``careful``), the JRC Fuzzy Safety Model (``fsm``) and RSS (``rss``), each a
longitudinal model on the EOAM's lane keeping and actuators (``controller``)."""

#: ``--driver`` names: the EOAM, then the reference drivers.
DRIVERS = ("eoam", "r157-cc", "fsm", "rss")
