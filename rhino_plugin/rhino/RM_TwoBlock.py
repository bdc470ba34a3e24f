#! python3
# venv: rockmech
# r: numpy==2.0.2, pydantic==2.13.5, trimesh==4.12.2, manifold3d==3.5.4, shapely==2.0.7, scipy==1.13.1, matplotlib==3.9.4
"""RM_TwoBlock: Two-block wall restrained top and bottom (A3): wall, base axis, overburden N, f_mt.

Writes <model>.<id>.spec.json and <model>.<id>.constants.json next to the saved .3dm file
(the headless ``rockmech constants`` inputs and output) and draws the axis, the centre of
mass and the hinges on the layer 'rockmech check'. Escape at any prompt writes nothing.
"""

from rhino_plugin.rhino.command import run_mechanism

# Rhino runs the script itself as the command.
run_mechanism("RM_TwoBlock")
