"""The spec refuses what the maths would answer wrongly, naming the field (issue #14)."""

from __future__ import annotations

import json
from typing import Any

import pytest

from shared_schema.errors import InputError
from shared_schema.spec import SPEC_VERSION, parse_spec


def wall(**extra: Any) -> dict[str, Any]:
    m: dict[str, Any] = {
        "id": "W",
        "groups": [{"objects": ["wall"], "density": 2000}],
        "axis": {"object": "axis"},
    }
    m.update(extra)
    return m


def loaded(**extra: Any) -> dict[str, Any]:
    return wall(typology="single_block_loaded", rocking="one_sided", **extra)


def two_block(**extra: Any) -> dict[str, Any]:
    return wall(typology="two_block", **extra)


def parse(*mechs: dict[str, Any], **top: Any) -> Any:
    return parse_spec(json.dumps({**top, "mechanisms": list(mechs)}), "spec.json")


def test_a_missing_spec_version_is_the_current_one_and_an_unknown_one_is_refused() -> None:
    assert parse(wall()).spec_version == SPEC_VERSION == "1.0"
    assert parse(wall(), spec_version="1.0").spec_version == "1.0"
    for bad in ("99", "2.0", "1", ""):
        with pytest.raises(InputError, match=r"spec_version: unknown spec_version .*reads .*'1.0'"):
            parse(wall(), spec_version=bad)


@pytest.mark.parametrize(
    ("mech", "field", "words"),
    [
        (
            wall(groups=[{"objects": ["wall", "wall"], "density": 2000}]),
            "groups[0].objects",
            "listed twice",
        ),
        (
            wall(groups=[{"objects": [{"id": "x"}, {"id": "x"}], "density": 2000}]),
            "groups[0].objects",
            "listed twice",
        ),
        (
            wall(groups=[{"objects": ["wall"], "density": 1e308}]),
            "groups[0].density",
            "at most 30000",
        ),
        (loaded(floors=[{"objects": ["f"], "density": 4e4}]), "floors[0].density", "at most 30000"),
        (loaded(floors=[{"objects": ["f", "f"], "density": 400}]), "floors[0].objects", "twice"),
        (loaded(roof={"objects": ["r"], "density": 1e308}), "roof.density", "at most 30000"),
        (
            loaded(tie_bars=[{"object": "t", "force": 1e300}]),
            "tie_bars[0].force",
            "at most 1e\\+09 N",
        ),
        (two_block(overburden={"force": 1e300}), "overburden.force", "at most 1e\\+09 N"),
        (
            two_block(overburden={"objects": ["s"], "density": 1e5}),
            "overburden.density",
            "at most 30000",
        ),
        (two_block(f_mt=1e308), "f_mt", "at most 1e\\+08 Pa"),
        (wall(axis={"start": [0, -1e300, 0], "end": [0, 1e300, 0]}), "axis", "beyond the largest"),
        (
            wall(cracks=[{"points": [[0, 0, 1], [1, 0, 1], [0, 1e7, 2]]}]),
            "cracks[0]",
            "beyond the largest",
        ),
        (
            wall(cracks=[{"points": [[0, 0, 1], [1, 0, 1], [0, 1, 2]], "keep_point": [2e6, 0, 0]}]),
            "cracks[0]",
            "keep_point: coordinate 2e\\+06",
        ),
    ],
)
def test_an_inadmissible_value_is_refused_naming_the_field(
    mech: dict[str, Any], field: str, words: str
) -> None:
    with pytest.raises(InputError, match=words) as err:
        parse(mech)
    assert f"(id 'W').{field}" in str(err.value), str(err.value)


def test_zero_overburden_and_zero_f_mt_stay_admissible() -> None:
    spec = parse(two_block(overburden={"force": 0.0}, f_mt=0.0))
    assert spec.mechanisms[0].plausibility_notes() == []


def test_implausible_values_are_admitted_with_a_note_naming_the_field() -> None:
    m = parse(
        loaded(
            groups=[{"objects": ["wall"], "density": 1.8}],
            floors=[{"objects": ["f"], "density": 2400}],
            roof={"objects": ["r"], "density": 150},
            tie_bars=[{"object": "t", "force": 2e4}, {"object": "u", "force": 5e7}],
        )
    ).mechanisms[0]
    notes = m.plausibility_notes()
    assert [n.split(" = ")[0] for n in notes] == [
        "W.groups[0].density",
        "W.roof.density",
        "W.tie_bars[1].force",
    ]
    assert "5e+07 N is outside the plausible range up to 1e+07 N" in notes[2]
    f = parse(two_block(f_mt=5e6, overburden={"force": 2e7})).mechanisms[0]
    assert [n.split(" = ")[0] for n in f.plausibility_notes()] == ["W.overburden.force", "W.f_mt"]
