#! python3
# venv: rockmech
# r: numpy==2.0.2, pydantic==2.13.5, trimesh==4.12.2, manifold3d==3.5.4, shapely==2.0.7, scipy==1.13.1, matplotlib==3.9.4
"""RM_Retrofit: tie-bars for the mechanisms that fail the 2019 checks, drawn on a layer.

Asks where the mechanisms come from: Constants (a constants file, a site file and a
retrofit spec) or SceneSearch (the document's objects searched with a search spec, then a
site file and a retrofit spec: the ties go into the scene and it is searched again). Runs
the retrofit through the Python API or, when the document user text 'rockmech_service_url'
is set, the REST service, writes <model>.retrofit/retrofit.json and draws each designed tie
on the layer 'rockmech retrofit' (from constants, its bars; from the scene, the tie-bar lines
the search again carried).
"""

from rhino_plugin.rhino.command import run_retrofit

# Rhino runs the script itself as the command.
run_retrofit()
