#! python3
# venv: rockmech
# r: numpy==2.0.2, pydantic==2.13.5, trimesh==4.12.2, manifold3d==3.5.4, shapely==2.0.7, scipy==1.13.1, matplotlib==3.9.4
"""RM_Analyse: envelopes and critical bands, time histories or a pulse on constants files.

Takes the current model's <model>.*.constants.json files or any constants file, runs
through the Python API or, when the document user text 'rockmech_service_url' is set, the
REST service, then shows the plot and a summary. Results go to <model>.analysis/.
"""

from rhino_plugin.rhino.command import run_analyse

# Rhino runs the script itself as the command.
run_analyse()
