"""V6 of issue #31: published numbers.

On a tilting table every rigid-body mechanism starts when ``tan θ = λ0`` (gravity turns by θ
relative to the structure: ``sin θ`` drives, ``cos θ`` restores), so a tilt test measures the
static multiplier directly. The one published criterion transcribed here is the rigid
block's (Housner 1963, read for docs/theory.md §2.1 and §8.5): a block of half-width b and
half-height h uplifts under a lateral acceleration ``g tan α``, ``α = atan(b/h)``, so on a
tilting table it overturns when the tilt reaches α, whatever its size or density.

Not transcribed, and so not a test: the 42 tilting-table configurations (1:5 dry marble
walls varying length, openings, staggering, wall-to-wall connection, overburden and storeys)
of Restrepo-Vélez, Magenes & Griffith (2014), *Int. J. Archit. Herit.* 8(1):1–28, whose
measured multipliers were not available to this project, and the tables of Funari, Mehrotra
& Lourenço (2021), *Appl. Sci.* 11(3):942 (docs/search.md, Validation). When those tables
are obtained, their rows belong here with the source named beside each number.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from search_scenes import BUILD

from cad_maths.scenes import read_scene
from cad_maths.search.engine import run_search
from shared_schema.search import SearchSpec


@pytest.mark.parametrize(
    ("thickness", "height", "density"),
    [(0.5, 3.0, 1800.0), (0.3, 2.0, 2400.0), (1.0, 1.0, 1600.0), (0.8, 0.6, 2000.0)],
)
def test_v6_housner_tilted_plane_overturns_at_the_slenderness_angle(
    tmp_path: Path, thickness: float, height: float, density: float
) -> None:
    b = BUILD.Builder("tilt")
    b.box("block", "Walls", (0.0, 0.0, 0.0), (thickness, 2.0, height), "stone")
    path = b.write(tmp_path / "tilt.3dm")
    spec = SearchSpec.model_validate(
        {"walls": [{"id": "B", "object": "block", "density": density}], "lp": False}
    )
    res = run_search(read_scene(path), spec, lp=False)
    full = [c for c in res.candidates if c.family == "overturning"]
    assert full, [c.label for c in res.candidates]
    tilt = math.degrees(math.atan(min(c.lam0 for c in full)))
    alpha = math.degrees(math.atan((thickness / 2.0) / (height / 2.0)))
    assert tilt == pytest.approx(alpha, abs=1e-9)
