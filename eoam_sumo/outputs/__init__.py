"""Output folders written safely: one process at a time (``lock``), a finished folder
replaced only by a complete new one (``staging``)."""
