"""The example scenes' builder (``examples/scenes/build_scenes.py``), loaded once for the CAD tests.

``examples/`` is not a package, so the tests that draw their own small ``.3dm`` scenes with its
``Builder`` import it from here: ``from cad_scenes import BUILD``.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location(
    "build_scenes_cad", REPO / "examples" / "scenes" / "build_scenes.py"
)
assert _spec is not None and _spec.loader is not None
#: The builder module: ``Builder``, ``ring_solid``, ``grid_box_solid``, the example scenes.
BUILD: Any = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(BUILD)
