"""rockmech inside Rhino 8: the prompt flows, the command scripts and Grasshopper components.

The maths they call (scene readers, geometry, mechanisms, the search) is ``cad_maths``.
Everything Rhino 8 imports from here must stay CPython 3.9-clean
(CONTRIBUTING.md, "The house").
"""
