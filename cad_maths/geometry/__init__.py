"""Pure geometry on triangle meshes: mass properties, cuts, contacts, welding, triangulation.

Runs inside Rhino 8 (CPython 3.9) and headless; numpy, trimesh, manifold3d and shapely only.
"""
