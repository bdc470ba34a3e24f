"""Bad mechanism specs through ``rockmech constants SCENE SPEC -o OUT`` (issue #14 corpus).

Each case takes a bundled example spec (``examples/specs``), changes one thing, and runs it on
the bundled scene it belongs to. A bad spec must get exit status 2 and ``error: <field>: ...``
naming the field; never a traceback. Cases the code still answers wrongly are strict-xfail
with their #14 class.
"""

from __future__ import annotations

import copy
import gzip
import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from corpus_case import Case, params, run_case

from shared_schema.rules import quantity_note

REPO = Path(__file__).resolve().parents[2]
SCENES = REPO / "examples" / "scenes"
SPECS = REPO / "examples" / "specs"

Spec = dict[str, Any]


def _base(scene: str) -> Spec:
    doc: Spec = json.loads((SPECS / f"{scene}.spec.json").read_text())
    return doc


def _m0(doc: Spec) -> dict[str, Any]:
    mech: dict[str, Any] = doc["mechanisms"][0]
    return mech


def _set(path: str, value: Any) -> Callable[[Spec], Spec]:
    """A change setting ``path`` (dots; ``m`` is the first mechanism) to ``value``."""

    def change(doc: Spec) -> Spec:
        keys = path.split(".")
        node: Any = _m0(doc) if keys[0] == "m" else doc
        for k in keys[1:-1] if keys[0] == "m" else keys[:-1]:
            node = node[int(k)] if isinstance(node, list) else node[k]
        last = keys[-1]
        if isinstance(node, list):
            node[int(last)] = value
        else:
            node[last] = value
        return doc

    return change


def _drop(path: str) -> Callable[[Spec], Spec]:
    """A change removing ``path`` (``m.key`` or a top-level key)."""

    def change(doc: Spec) -> Spec:
        keys = path.split(".")
        node: Any = _m0(doc) if keys[0] == "m" else doc
        for k in keys[1:-1] if keys[0] == "m" else keys[:-1]:
            node = node[int(k)] if isinstance(node, list) else node[k]
        del node[keys[-1]]
        return doc

    return change


def _raw(text: str) -> Callable[[Spec], str]:
    return lambda _doc: text


#: (id, scene, change, expect, field, problem[, xfail]); a change returns the new spec (a dict,
#: or text written as is).
SpecCase = tuple[Any, ...]

AXIS_SAME = {"start": [0.0, 0.0, 0.0], "end": [0.0, 0.0, 0.0]}
AXIS_FAR = {"start": [1000.0, 0.0, 0.0], "end": [1000.0, 1.0, 0.0]}
AXIS_MM = {"start": [0.0, 0.0, 0.0], "end": [0.0, 500.0, 0.0]}


def _two(doc: Spec) -> Spec:
    """Duplicate the first mechanism (same id)."""
    doc["mechanisms"].append(copy.deepcopy(_m0(doc)))
    return doc


def _nest(depth: int) -> Callable[[Spec], Spec]:
    def change(doc: Spec) -> Spec:
        value: Any = 1
        for _ in range(depth):
            value = {"a": value}
        _m0(doc)["name"] = value
        return doc

    return change


def _same_p_eq(p_eq: float) -> Callable[[Any], bool]:
    """A check that the first mechanism's positive p_eq is ``p_eq`` (to 4 digits) [rad/s]."""
    return lambda d: abs(d["mechanisms"][0]["positive"]["p_eq"] - p_eq) < 1e-3


SPEC_CASES: list[SpecCase] = [
    ("ok-rect", "rect_wall", lambda d: d, "ok", "", ""),
    ("ok-facade", "facade", lambda d: d, "ok", "", ""),
    # the file itself
    # #25: what was expected, what was found and what to do
    (
        "empty-file",
        "rect_wall",
        _raw(""),
        "error",
        "spec",
        r"spec\.json is empty \(0 bytes\): expected a mechanism spec \(JSON",
    ),
    ("not-json", "rect_wall", _raw("{mechanisms: ["), "error", "spec", "JSON"),
    ("json-list", "rect_wall", _raw("[1, 2]"), "error", "spec|mechanisms", "object|dict|type"),
    ("json-null", "rect_wall", _raw("null"), "error", "spec|mechanisms", "object|dict|type"),
    ("json-string", "rect_wall", _raw('"spec"'), "error", "spec|mechanisms", "object|dict|type"),
    (
        "deep-nesting-file",
        "rect_wall",
        _raw("[" * 5000 + "]" * 5000),
        "error",
        "spec",
        "nest|deep|JSON|object",
    ),
    (
        "binary",
        "rect_wall",
        lambda d: bytes(range(256)) * 4,
        "error",
        "spec",
        r"spec\.json is not a text file \(binary data .*expected a mechanism spec",
    ),
    # UTF-16 with its byte-order mark (a PowerShell redirect) is read, as every text input (#25)
    ("utf16", "rect_wall", lambda d: json.dumps(d).encode("utf-16"), "ok", "", ""),
    (
        "nan-literal",
        "rect_wall",
        _raw(json.dumps(_base("rect_wall")).replace("1800", "NaN")),
        "error",
        "density",
        "finite|nan|greater",
    ),
    (
        "infinity-literal",
        "rect_wall",
        _raw(json.dumps(_base("rect_wall")).replace("1800", "Infinity")),
        "error",
        "density",
        "finite|inf|greater",
    ),
    # top level
    ("no-mechanisms", "rect_wall", _drop("mechanisms"), "error", "mechanisms", "missing|required"),
    ("mechanisms-empty", "rect_wall", _set("mechanisms", []), "error", "mechanisms", "at least|1"),
    (
        "mechanisms-dict",
        "rect_wall",
        _set("mechanisms", {"W1": {}}),
        "error",
        "mechanisms",
        "list|array",
    ),
    ("mechanisms-null", "rect_wall", _set("mechanisms", None), "error", "mechanisms", "list|array"),
    (
        "mechanism-string",
        "rect_wall",
        _set("mechanisms", ["W1"]),
        "error",
        "mechanisms",
        "dict|object",
    ),
    ("units-furlong", "rect_wall", _set("units", "furlong"), "error", "units", "m|mm|cm"),
    ("units-number", "rect_wall", _set("units", 1000), "error", "units", "m|mm|cm"),
    ("units-mm-scales", "rect_wall", _set("units", "mm"), "ok", "", ""),
    (
        "spec-version-bad",
        "rect_wall",
        _set("spec_version", "99"),
        "error",
        "spec_version",
        "version|support",
    ),
    (
        "top-unknown-key",
        "rect_wall",
        _set("colour", "red"),
        "error",
        "colour",
        "extra|not permitted|unknown",
    ),
    # id and names
    ("id-missing", "rect_wall", _drop("m.id"), "error", "id", "missing|required"),
    ("id-empty", "rect_wall", _set("m.id", ""), "error", "id", "at least|empty|1 char"),
    ("id-number", "rect_wall", _set("m.id", 7), "error", "id", "str"),
    ("id-nested", "rect_wall", _set("m.id", {"a": {"b": 1}}), "error", "id", "str"),
    ("id-duplicate", "rect_wall", _two, "error", "id|mechanisms", "duplicate|twice|unique"),
    ("name-nested-deep", "rect_wall", _nest(50), "error", "name", "str"),
    (
        "mech-unknown-key",
        "rect_wall",
        _set("m.colour", "red"),
        "error",
        "colour",
        "extra|not permitted|unknown",
    ),
    # typology and rocking
    (
        "typology-unknown",
        "rect_wall",
        _set("m.typology", "three_block"),
        "error",
        "typology",
        "single_block|two_block",
    ),
    (
        "typology-number",
        "rect_wall",
        _set("m.typology", 1),
        "error",
        "typology",
        "single_block|two_block",
    ),
    (
        "typology-case",
        "rect_wall",
        _set("m.typology", "Single_Block"),
        "error",
        "typology",
        "single_block",
    ),
    (
        "typology-multi-without-blocks",
        "rect_wall",
        _set("m.typology", "multi_block"),
        "error",
        "blocks|hinges",
        "need|required|missing",
    ),
    (
        "rocking-unknown",
        "rect_wall",
        _set("m.rocking", "three_sided"),
        "error",
        "rocking",
        "two_sided|one_sided",
    ),
    (
        "rocking-bool",
        "rect_wall",
        _set("m.rocking", True),
        "error",
        "rocking",
        "two_sided|one_sided",
    ),
    # groups and densities
    ("groups-missing", "rect_wall", _drop("m.groups"), "error", "groups", "need|required|missing"),
    ("groups-empty", "rect_wall", _set("m.groups", []), "error", "groups", "at least|1"),
    (
        "groups-not-list",
        "rect_wall",
        _set("m.groups", {"objects": ["wall"]}),
        "error",
        "groups",
        "list|array",
    ),
    (
        "density-missing",
        "rect_wall",
        _drop("m.groups.0.density"),
        "error",
        "density",
        "missing|required",
    ),
    (
        "density-negative",
        "rect_wall",
        _set("m.groups.0.density", -1800),
        "error",
        "density",
        "greater than 0|> 0",
    ),
    (
        "density-zero",
        "rect_wall",
        _set("m.groups.0.density", 0),
        "error",
        "density",
        "greater than 0|> 0",
    ),
    (
        "density-1e308",
        "rect_wall",
        _set("m.groups.0.density", 1e308),
        "error",
        "density",
        "range|at most|implausible|<=",
    ),
    # a single block's p_eq and lam do not depend on its density: the right answer is the base one
    (
        "density-tiny",
        "rect_wall",
        _set("m.groups.0.density", 1e-3),
        "ok",
        "",
        "",
        "",
        _same_p_eq(2.199),
    ),
    (
        "density-lead",
        "rect_wall",
        _set("m.groups.0.density", 11340),
        "ok",
        "",
        "",
        "",
        _same_p_eq(2.199),
    ),
    (
        "density-string",
        "rect_wall",
        _set("m.groups.0.density", "1800"),
        "error",
        "density",
        "number|float",
    ),
    (
        "density-text",
        "rect_wall",
        _set("m.groups.0.density", "heavy"),
        "error",
        "density",
        "number|float",
    ),
    (
        "density-bool",
        "rect_wall",
        _set("m.groups.0.density", True),
        "error",
        "density",
        "number|float",
    ),
    (
        "density-null",
        "rect_wall",
        _set("m.groups.0.density", None),
        "error",
        "density",
        "number|float",
    ),
    (
        "density-list",
        "rect_wall",
        _set("m.groups.0.density", [1800]),
        "error",
        "density",
        "number|float",
    ),
    (
        "objects-empty",
        "rect_wall",
        _set("m.groups.0.objects", []),
        "error",
        "objects",
        "at least|1",
    ),
    (
        "objects-string",
        "rect_wall",
        _set("m.groups.0.objects", "wall"),
        "error",
        "objects",
        "list|array",
    ),
    (
        "object-unknown",
        "rect_wall",
        _set("m.groups.0.objects", ["nope"]),
        "error",
        "nope",
        "not found|no object|unknown",
    ),
    (
        "object-number",
        "rect_wall",
        _set("m.groups.0.objects", [3]),
        "error",
        "objects",
        "str|selector",
    ),
    (
        "object-is-axis-line",
        "rect_wall",
        _set("m.groups.0.objects", ["axis"]),
        "error",
        "axis|objects",
        "solid|mesh|closed|line|curve",
    ),
    (
        "object-listed-twice",
        "rect_wall",
        _set("m.groups.0.objects", ["wall", "wall"]),
        "error",
        "wall|objects",
        "twice|duplicate|more than once",
    ),
    ("label-number", "rect_wall", _set("m.groups.0.label", 5), "error", "label", "str"),
    # axis
    ("axis-missing", "rect_wall", _drop("m.axis"), "error", "axis", "need|required|missing"),
    (
        "axis-object-unknown",
        "rect_wall",
        _set("m.axis", {"object": "nope"}),
        "error",
        "nope|axis",
        "not found|no object",
    ),
    (
        "axis-object-is-solid",
        "rect_wall",
        _set("m.axis", {"object": "wall"}),
        "error",
        "axis|wall",
        "line|curve",
    ),
    ("axis-empty", "rect_wall", _set("m.axis", {}), "error", "axis", "object|start|end"),
    (
        "axis-both",
        "rect_wall",
        _set("m.axis", {"object": "axis", **AXIS_MM}),
        "error",
        "axis",
        "either|both|one of",
    ),
    (
        "axis-identical-points",
        "rect_wall",
        _set("m.axis", AXIS_SAME),
        "error",
        "axis",
        "same|identical|coincide|zero length|distinct",
    ),
    (
        "axis-far-from-body",
        "rect_wall",
        _set("m.axis", AXIS_FAR),
        "error",
        "axis",
        "far|away|units|outside|not on|contact",
    ),
    (
        "axis-start-two-coords",
        "rect_wall",
        _set("m.axis", {"start": [0, 0], "end": [0, 1, 0]}),
        "error",
        "start|axis",
        "3|three",
    ),
    (
        "axis-start-strings",
        "rect_wall",
        _set("m.axis", {"start": ["a", "b", "c"], "end": [0, 1, 0]}),
        "error",
        "start|axis",
        "number|float",
    ),
    (
        "axis-start-nan",
        "rect_wall",
        _raw(
            json.dumps(
                {
                    **_base("rect_wall"),
                    "mechanisms": [
                        {**_m0(_base("rect_wall")), "axis": {"start": [0, 0, 0], "end": [0, 1, 0]}}
                    ],
                }
            ).replace("[0, 1, 0]", "[NaN, 1, 0]")
        ),
        "error",
        "end|axis",
        "finite|nan",
    ),
    (
        "axis-huge",
        "rect_wall",
        _set("m.axis", {"start": [0, -1e300, 0], "end": [0, 1e300, 0]}),
        "error",
        "axis|start|end",
        "range|far|finite|at most|units",
    ),
    (
        "axis-vertical",
        "rect_wall",
        _set("m.axis", {"start": [0, 0, 0], "end": [0, 0, 1]}),
        "error",
        "axis",
        "horizontal|vertical|incline",
    ),
    ("axis-negative-missing-two-sided", "scan_wall", _drop("m.axis_negative"), "ok", "", ""),
    # cracks
    (
        "crack-misses-body",
        "facade",
        lambda d: (
            d["mechanisms"][1].update(
                {"cracks": [{"points": [[100, 0, 100], [101, 0, 100], [100, 1, 100]]}]}
            ),
            d,
        )[1],
        "error",
        "crack",
        "miss|does not cut|outside|intersect|whole",
    ),
    (
        "crack-collinear-points",
        "facade",
        lambda d: (
            d["mechanisms"][1].update({"cracks": [{"points": [[0, 0, 1], [1, 0, 1], [2, 0, 1]]}]}),
            d,
        )[1],
        "error",
        "crack|points",
        "collinear|line|plane|distinct",
    ),
    (
        "crack-two-points",
        "facade",
        lambda d: (d["mechanisms"][1].update({"cracks": [{"points": [[0, 0, 1], [1, 0, 1]]}]}), d)[
            1
        ],
        "error",
        "points|crack",
        "3|three",
    ),
    (
        "crack-object-unknown",
        "facade",
        lambda d: (d["mechanisms"][1].update({"cracks": [{"object": "nope"}]}), d)[1],
        "error",
        "nope|crack",
        "not found|no object",
    ),
    (
        "crack-keep-bad",
        "facade",
        lambda d: (d["mechanisms"][1]["cracks"][0].update({"keep": "upper"}), d)[1],
        "error",
        "keep",
        "axis_side|positive|negative",
    ),
    (
        "crack-empty",
        "facade",
        lambda d: (d["mechanisms"][1].update({"cracks": [{}]}), d)[1],
        "error",
        "crack",
        "object|points",
    ),
    # loads of a loaded wall
    (
        "tie-force-zero",
        "facade",
        _set("m.tie_bars.0.force", 0),
        "error",
        "force",
        "greater than 0|> 0",
    ),
    (
        "tie-force-negative",
        "facade",
        _set("m.tie_bars.0.force", -2e4),
        "error",
        "force",
        "greater than 0|> 0",
    ),
    (
        "tie-force-1e300",
        "facade",
        _set("m.tie_bars.0.force", 1e300),
        "error",
        "force",
        "range|at most|implausible|<=",
    ),
    (
        "tie-force-string",
        "facade",
        _set("m.tie_bars.0.force", "20 kN"),
        "error",
        "force",
        "number|float",
    ),
    (
        "tie-object-unknown",
        "facade",
        _set("m.tie_bars.0.object", "nope"),
        "error",
        "nope|tie",
        "not found|no object",
    ),
    (
        "floor-density-zero",
        "facade",
        _set("m.floors.0.density", 0),
        "error",
        "density",
        "greater than 0|> 0",
    ),
    (
        "floor-tributary-2",
        "facade",
        _set("m.floors.0.tributary", 2.0),
        "error",
        "tributary",
        "less than or equal|<= 1|1",
    ),
    (
        "floor-level-huge",
        "facade",
        _set("m.floors.0.level", 1e308),
        "error",
        "level",
        "extra|not permitted|unknown",
    ),
    ("roof-tied-string", "facade", _set("m.roof.tied", "maybe"), "error", "tied", "bool"),
    (
        "vault-class-bad",
        "facade",
        _set("m.vaults.0.construction_class", "z"),
        "error",
        "construction_class",
        "a|b|c",
    ),
    ("f-mt-negative", "two_block_wall", _set("m.f_mt", -1.0), "error", "f_mt", "greater|>|>="),
    (
        "f-mt-1e308",
        "two_block_wall",
        _set("m.f_mt", 1e308),
        "error",
        "f_mt",
        "range|at most|implausible|<=",
    ),
    (
        "overburden-force-negative",
        "two_block_wall",
        _set("m.overburden", {"force": -5.0}),
        "error",
        "force",
        "greater than or equal|>= 0",
    ),
    (
        "overburden-empty",
        "two_block_wall",
        _set("m.overburden", {}),
        "error",
        "overburden",
        "objects|force|density",
    ),
    # ranges and plausibility (shared_schema.rules.QUANTITY_RANGES)
    (
        "floor-density-1e308",
        "facade",
        _set("m.floors.0.density", 1e308),
        "error",
        "floors\\[0\\].density",
        "at most 30000",
    ),
    (
        "roof-density-above-osmium",
        "facade",
        _set("m.roof.density", 40000),
        "error",
        "roof.density",
        "at most 30000",
    ),
    (
        "overburden-force-1e300",
        "two_block_wall",
        _set("m.overburden", {"force": 1e300}),
        "error",
        "overburden.force",
        "at most 1e\\+09 N",
    ),
    (
        "overburden-density-1e308",
        "two_block_wall",
        _set("m.overburden.density", 1e308),
        "error",
        "overburden.density",
        "at most 30000",
    ),
    (
        "block-density-1e308",
        "portal_frame",
        _set("m.blocks.1.0.density", 1e308),
        "error",
        "density",
        "at most 30000",
    ),
    (
        "density-in-t-per-m3",
        "rect_wall",
        _set("m.groups.0.density", 1.8),
        "warn",
        "",
        "groups\\[0\\].density = 1.8 kg/m\\^3 is outside the plausible range",
    ),
    (
        "tie-force-50-MN",
        "facade",
        _set("m.tie_bars.0.force", 5e7),
        "warn",
        "",
        "tie_bars\\[0\\].force = 5e\\+07 N is outside the plausible range",
    ),
    (
        "f-mt-in-kPa-as-Pa-times-1000",
        "two_block_wall",
        _set("m.f_mt", 1e8),
        "warn",
        "",
        "f_mt = 1e\\+08 Pa is outside the plausible range",
    ),
    (
        "object-in-two-groups",
        "rect_wall",
        _set(
            "m.groups",
            [{"objects": ["wall"], "density": 1800}, {"objects": ["wall"], "density": 900}],
        ),
        "error",
        "groups",
        "listed in two density groups",
    ),
    (
        "block-object-in-two-blocks",
        "portal_frame",
        _set("m.blocks.1.0.objects", ["column_left"]),
        "error",
        "blocks",
        "listed in two density groups",
    ),
    ("spec-version-current", "rect_wall", _set("spec_version", "1.0"), "ok", "", ""),
    (
        "hinge-point-huge",
        "portal_frame",
        _set("m.hinges.A", [0.0, 1e300, 0.0]),
        "error",
        "hinges.A",
        "beyond the largest",
    ),
    (
        "crack-keep-point-inf-literal",
        "facade",
        lambda d: json.dumps(
            (d["mechanisms"][1]["cracks"][0].update({"keep_point": [0.0, 1.0, 1e400]}), d)[1]
        ).replace("Infinity", "1e400"),
        "error",
        "keep_point|cracks",
        "finite|inf",
    ),
    # eta
    (
        "eta-over-1",
        "rect_wall",
        _set("m.eta", 1.5),
        "error",
        "eta",
        "less than or equal|<= 1|\\[-1, 1\\]",
    ),
    (
        "eta-below-minus-1",
        "rect_wall",
        _set("m.eta", -1.5),
        "error",
        "eta",
        "greater than or equal|>= -1|\\[-1, 1\\]",
    ),
    (
        "eta-negative-two-sided",
        "rect_wall",
        _set("m.eta", -0.5),
        "error",
        "eta",
        ">= 0|two_sided|negative",
    ),
    ("eta-string", "rect_wall", _set("m.eta", "0.9"), "error", "eta", "number|float"),
    ("eta-rule-bad", "facade", _set("m.eta_rule", "magic"), "error", "eta_rule", "one_sided"),
    # multi-block hinges
    (
        "hinges-missing",
        "portal_frame",
        _drop("m.hinges"),
        "error",
        "hinges",
        "need|required|missing",
    ),
    (
        "hinge-unknown-object",
        "portal_frame",
        _set("m.hinges.A", "nope"),
        "error",
        "nope|hinge",
        "not found|no object",
    ),
    (
        "hinge-same-as-other",
        "portal_frame",
        _set("m.hinges.B", "hinge_A"),
        "error",
        "hinge",
        "same|identical|distinct|coincide",
    ),
    (
        "hinges-extra-key",
        "portal_frame",
        _set("m.hinges.E", "hinge_A"),
        "error",
        "E|hinges",
        "extra|not permitted|unknown",
    ),
    (
        "blocks-two",
        "portal_frame",
        lambda d: (_m0(d)["blocks"].pop(), d)[1],
        "error",
        "blocks",
        "3|three",
    ),
    (
        "blocks-density-neg",
        "portal_frame",
        _set("m.blocks.1.0.density", -1),
        "error",
        "density",
        "greater than 0|> 0",
    ),
    (
        "allow-axis-string",
        "rect_wall",
        _set("m.allow_non_horizontal_axis", "yes please"),
        "error",
        "allow_non_horizontal_axis",
        "bool",
    ),
    (
        "amplification-negative",
        "rect_wall",
        _set("m.amplification", {"f_n": -1.0, "h_e": 4.0, "h": 3.0}),
        "error",
        "f_n|amplification",
        "greater|>",
    ),
    # issue #25: a line break in an id broke the terminal table (and the error line)
    (
        "id-with-newline",
        "rect_wall",
        _set("m.id", "W1\nW2"),
        "error",
        r"mechanisms\[0\] \(id 'W1\\nW2'\)\.id",
        r"must be printable text, got the control character '\\n'$",
    ),
]


def _case(row: SpecCase) -> Case:
    cid, scene, _change, expect, fld, problem = row[:6]
    xfail = row[6] if len(row) > 6 else ""
    check = row[7] if len(row) > 7 else None
    argv = ["constants", str(SCENES / f"{scene}.3dm"), "{tmp}/spec.json", "-o", "{tmp}/out.json"]
    if check is not None:
        argv.append("--json")
    return Case(
        check=check,
        id=f"spec-{cid}",
        argv=argv,
        expect=expect,
        field=fld,
        problem=problem,
        xfail=xfail,
    )


CASES = [_case(r) for r in SPEC_CASES]
CHANGES = {f"spec-{r[0]}": (r[1], r[2]) for r in SPEC_CASES}


def _write_spec(case_id: str, tmp: Path) -> None:
    scene, change = CHANGES[case_id]
    spec = change(_base(scene))
    path = tmp / "spec.json"
    if isinstance(spec, bytes):
        path.write_bytes(spec)
    elif isinstance(spec, str):
        path.write_text(spec)
    else:
        path.write_text(json.dumps(spec))


@pytest.mark.parametrize("case", params(CASES))
def test_spec_case(case: Case, tmp_path: Path) -> None:
    _write_spec(case.id, tmp_path)
    argv = [a.replace("{tmp}", str(tmp_path)) for a in case.argv]
    run_case(case, argv)
    if case.expect == "error":
        assert not (tmp_path / "out.json").exists(), "a refused spec must write nothing"


def test_keep_going_writes_the_good_mechanism(tmp_path: Path) -> None:
    """``--keep-going``: the good mechanism is written, the bad one named, exit status 1."""
    doc = _base("facade")
    doc["mechanisms"][1]["cracks"] = [{"points": [[100, 0, 100], [101, 0, 100], [100, 1, 100]]}]
    (tmp_path / "spec.json").write_text(json.dumps(doc))
    out = tmp_path / "out.json"
    case = Case("keep-going", [], "partial", problem=r"F2")
    argv = ["constants", str(SCENES / "facade.3dm"), str(tmp_path / "spec.json"), "-o", str(out)]
    run_case(Case("no-keep-going", [], "error", "F2.cracks", "misses the body"), argv)
    assert not out.exists()
    run_case(case, [*argv, "--keep-going"])
    ids = [m["id"] for m in json.loads(out.read_text())["mechanisms"]]
    assert ids == ["F1"]


def test_spec_corpus_is_large() -> None:
    assert len(CASES) >= 90


# --- issue #36: the files a spec names, and the search's spec ---------------------------------

SEARCH_SCENE = SCENES / "search_facade.3dm"


def _search_spec(**change: Any) -> Spec:
    """The bundled search spec, quick to run (one family, 20 frequencies, no records)."""
    doc: Spec = json.loads((SPECS / "search_facade.search.json").read_text())
    doc["families"] = ["overturning"]
    doc["ranking"] = {"band_hz": [0.5, 10.0], "n_frequencies": 20, "records": [], "keep": 1}
    for key, value in change.items():
        doc[key] = value
    return doc


def _density(value: float) -> Spec:
    doc = _search_spec()
    doc["walls"][0]["density"] = value
    return doc


def _with_table(name: str) -> str:
    return json.dumps({**_base("rect_wall"), "thrust_table": name})


#: (id, files written into the case's folder, argv, expect, field, problem[, check])
FILE_CASES: list[tuple[Any, ...]] = [
    (
        "thrust-table-not-json",
        {"spec.json": _with_table("table.json"), "table.json": "class,rise_span\na,0.2\n"},
        "constants",
        "error",
        "thrust_table",
        r"table\.json: invalid JSON at line 1, column 1: .*expected a thrust table \(JSON text",
    ),
    (
        "thrust-table-not-utf8",
        {"spec.json": _with_table("table.json"), "table.json": b'{"source": "K\xf6ln"}'},
        "constants",
        "error",
        "thrust_table",
        r"table\.json is not UTF-8 text: byte 13 \(line 1\) is 0xf6, .*expected a thrust table"
        r".*save it again as UTF-8 text",
    ),
    (
        "thrust-table-a-list",
        {"spec.json": _with_table("table.json"), "table.json": "[]"},
        "constants",
        "error",
        "thrust_table",
        r"table\.json: the top level is list, not an object; expected a thrust table",
    ),
    (
        "thrust-table-missing",
        {"spec.json": _with_table("table.json")},
        "constants",
        "error",
        "thrust_table",
        r"file not found: .*table\.json",
    ),
    (
        "search-spec-empty",
        {"s.search.json": "  \n"},
        "search",
        "error",
        "spec",
        r"s\.search\.json holds only blank space: expected a search spec \(JSON",
    ),
    (
        "search-spec-gzip",
        {"s.search.json": gzip.compress(json.dumps(_search_spec()).encode())},
        "search",
        "error",
        "spec",
        r"s\.search\.json is not a text file \(it starts like a gzip archive\): expected a "
        r"search spec \(JSON",
    ),
    (
        "search-spec-not-json",
        {"s.search.json": "{walls: ["},
        "search",
        "error",
        "spec",
        r"s\.search\.json: invalid JSON at line 1, column 2: .*expected a search spec",
    ),
    (
        # t/m^3 for kg/m^3: a warning as in a mechanism spec (rules.quantity_note), not a note
        "search-density-1.8",
        {"s.search.json": json.dumps(_density(1.8))},
        "search",
        "warn",
        "",
        r"warning: walls\[0\]\.density = 1\.8 kg/m\^3 is outside the plausible range \[300, "
        r"9000\] kg/m\^3: .*t/m\^3",
        lambda d: (
            d["warnings"] == [quantity_note(1.8, "density", "walls[0].density")]
            and not any("density" in n for n in d["notes"])
        ),
    ),
    (
        "search-density-1800-no-warning",
        {"s.search.json": json.dumps(_density(1800.0))},
        "search",
        "ok",
        "",
        "",
        lambda d: d["warnings"] == [],
    ),
]


def _file_case(row: tuple[Any, ...]) -> Case:
    cid, files, command, expect, fld, problem = row[:6]
    check = row[6] if len(row) > 6 else None
    if command == "constants":
        argv = [command, str(SCENES / "rect_wall.3dm"), "{tmp}/spec.json", "-o", "{tmp}/out.json"]
    else:
        argv = [command, str(SEARCH_SCENE), "{tmp}/s.search.json", "-o", "{tmp}/out"]
        argv.append("--no-figure")
    if check is not None:
        argv.append("--json")
    return Case(f"{cid}", argv, expect, fld, problem, check=check, files=files)


FILE_CASE_LIST = [_file_case(r) for r in FILE_CASES]


@pytest.mark.parametrize("case", params(FILE_CASE_LIST))
def test_file_case(case: Case, tmp_path: Path) -> None:
    for name, content in case.files.items():
        path = tmp_path / name
        if isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content)
    argv = [a.replace("{tmp}", str(tmp_path)) for a in case.argv]
    run_case(case, argv)
    if case.expect == "error":
        assert not (tmp_path / "out.json").exists() and not (tmp_path / "out").exists()
