"""rockmech's CAD side: scene reading and geometry maths, from drawn solids to kinematic constants.

Everything Rhino 8 imports from here must stay CPython 3.9-clean (see STYLE.md).
"""
