#! python3
# venv: rockmech
# r: numpy==2.0.2, pydantic==2.13.5, trimesh==4.12.2, manifold3d==3.5.4, shapely==2.0.7, scipy==1.13.1, matplotlib==3.9.4
"""RM_Search: find the document's façade mechanisms and rank them by how they rock.

Asks for a search spec (JSON), searches the document's objects through the Python API or,
when the document user text 'rockmech_service_url' is set, the REST service, writes
<model>.search/ and draws the best ranked mechanisms on the layer 'rockmech search'.
"""

from rhino_plugin.rhino.command import run_search

# Rhino runs the script itself as the command.
run_search()
