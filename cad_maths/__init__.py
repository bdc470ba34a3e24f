"""rockmech's CAD maths, free of Rhino: scene readers, mesh geometry, mechanisms, the search.

From drawn solids (a ``.3dm`` file read by rhino3dm, a scanned mesh, or Rhino's own objects
handed over by ``rhino_plugin``) to the kinematic constants of each mechanism: the scene
readers (``scenes``, ``scene_3dm``, ``scene_mesh``, ``scene_base`` and the ``.3dm`` archive
check ``archive_3dm``), mesh geometry (``geometry``), the mechanism builders
(``mechanisms``) and the automatic mechanism search (``search``). Imports ``shared_schema``
only (and numpy, scipy, rhino3dm, trimesh, manifold3d, shapely).

Rhino 8 imports this package: everything here must stay CPython 3.9-clean
(CONTRIBUTING.md, "The house").
"""
