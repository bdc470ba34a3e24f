"""Automatic search of a façade's collapse mechanisms (issue #31), Rhino-free maths.

``building_from_scene`` reads the walls (as prisms), junctions, levels and ties a search
spec names; ``families`` enumerates and refines the candidate mechanisms on the exact static
load multiplier λ0; ``lp`` checks the catalogue with an upper-bound linear programme over all
candidate lines; ``specs`` turns each candidate into a mechanism spec of an existing typology
for the constants builder; ``engine.run_search`` does all of it. The ranking by rocking
response and the documents are in ``solver_service.workflows.search``.

Python 3.9-clean: imported by Rhino 8.
"""
