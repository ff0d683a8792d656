"""ASAM OpenSCENARIO 1.x scenarios over OpenDRIVE roads, run through SUMO (docs/openscenario.md).

Reading (:mod:`.reader`: parameters resolved first, catalogs expanded, every element checked
against the supported subset) is apart from running (:mod:`.compile` turns the storyboard into
a timeline of scripted speeds, :mod:`.sumofiles` writes the SUMO scenario, :mod:`.runner`
hands it to the ordinary run).
"""
