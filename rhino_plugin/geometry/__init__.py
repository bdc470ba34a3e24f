"""Pure geometry on triangle meshes: mass properties, inertia about an axis, cuts, contacts.

Runs inside Rhino 8 (CPython 3.9) and headless; numpy, trimesh, manifold3d and shapely only.
"""
