"""The search's typed document (#38): ``search.json`` is ``SearchDocument.to_dict()``.

``rockmech search`` writes the document of the typed model byte for byte (key order, ints,
absent sections), ``rockmech.search`` returns it with attributes a script reads (the
rankings, each candidate's λ0, ``find(id)``), and the model refuses a key it does not know.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from pydantic import ValidationError
from search_scenes import EXAMPLE_SCENE, EXAMPLE_SPEC, two_block_wall
from typer.testing import CliRunner

import rockmech
from shared_schema.documents.search import SearchCandidate, SearchDocument
from shared_schema.errors import InputError
from shared_schema.rules import G
from solver_service.cli import app

B, H, L, RHO = 0.3, 3.0, 1.0, 1800.0


def test_the_command_writes_the_typed_documents_json_byte_for_byte(tmp_path: Path) -> None:
    out = tmp_path / "out"
    res = CliRunner().invoke(
        app, ["search", str(EXAMPLE_SCENE), str(EXAMPLE_SPEC), "--no-figure", "-o", str(out)]
    )
    assert res.exit_code == 0, res.output
    text = (out / "search.json").read_text(encoding="utf-8")
    doc = SearchDocument.model_validate(json.loads(text))
    assert json.dumps(doc.to_dict(), indent=1, allow_nan=False) + "\n" == text
    assert SearchDocument.model_validate_json(text).to_dict() == doc.to_dict()
    # the example's spec names a site and a record: every optional section is there
    assert doc.code_check is not None and doc.records and doc.records[0].record == "elcentro_NS"
    top = doc.find(doc.rankings.dynamic[0])
    assert top.code_check is not None and top.records and top.overturning is not None
    # past the built ones a candidate has no dynamic sections, absent from the file
    raw = {c["id"]: c for c in json.loads(text)["candidates"]}
    for c in doc.candidates:
        assert ("overturning" in raw[c.id]) == (c.overturning is not None), c.id
        assert ("records" in raw[c.id]) == (c.records is not None), c.id


def test_the_document_refuses_a_key_it_does_not_know(tmp_path: Path) -> None:
    run = rockmech.search(EXAMPLE_SCENE, EXAMPLE_SPEC, records=[], site=None)
    good = run.doc.to_dict()
    assert SearchDocument.model_validate(good).to_dict() == good
    bad = json.loads(json.dumps(good))
    bad["candidates"][0]["lam_0"] = 0.2  # a misspelt key is not a candidate's
    with pytest.raises(ValidationError, match="lam_0"):
        SearchDocument.model_validate(bad)


def _two_block_lam(n: float, c: float) -> float:
    """λ* of a two-block wall under overburden ``n`` (docs/search.md, V1's closed form)."""
    w = RHO * G * B * H * L
    x = math.sqrt(c * n / (n + w))
    return 2.0 * B * (n + w) * (1.0 + x) ** 2 / (w * H)


def test_rockmech_search_returns_the_document_with_attributes(tmp_path: Path) -> None:
    scene = two_block_wall(tmp_path, B, H, L)
    w = RHO * G * B * H * L
    wall = {"id": "W", "object": "wall", "density": RHO, "overburden": {"force": w, "xi": 0.3}}
    slab = {"id": "S", "kind": "floor", "objects": ["slab"], "density": 2400.0, "tied": True}
    spec = {
        "walls": [wall],
        "levels": [slab],
        "families": ["vertical_flexure"],
        "ranking": {"n_frequencies": 20},
    }
    doc = rockmech.search(scene, spec).doc
    assert isinstance(doc, rockmech.SearchDocument)
    # least λ0 first, ranked statically in that order
    assert doc.rankings.static == [c.id for c in doc.candidates]
    assert [c.rank_static for c in doc.candidates] == list(range(1, len(doc.candidates) + 1))
    assert [c.lam0 for c in doc.candidates] == sorted(c.lam0 for c in doc.candidates)
    by_direction = {c.direction: c for c in doc.candidates}
    # outward, N rises by b (1 + c h1/h2) with c = 1 - xi; inward c = xi
    for direction, c in (("outward", 0.7), ("inward", 0.3)):
        cand = doc.find(by_direction[direction].id)
        assert isinstance(cand, SearchCandidate) and cand.typology == "two_block"
        assert cand.lam0 == pytest.approx(_two_block_lam(w, c), rel=1e-12)
        assert cand.builder is not None and cand.builder.agrees
        assert cand.overturning is not None and cand.rank_dynamic is not None
    assert [c.id for c in doc.ranked] == doc.rankings.dynamic
    assert doc.counts.candidates == len(doc.candidates) == doc.counts.built
    with pytest.raises(InputError, match="no mechanism 'S99'") as err:
        doc.find("S99")
    assert err.value.field == "mechanism"
