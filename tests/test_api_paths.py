"""Paths the Python way in the public API (#38).

Every function of docs/api.md that reads a file takes the path as a ``str`` or a
``pathlib.Path`` and gives the same result for both; a missing file, a folder, or an
argument that is not a path (bytes, an open file, a number) is a ``rockmech.InputError``
naming the argument and, for a file, the path: never an ``AttributeError`` or a
``TypeError`` from inside a reader. The functions that write take ``str`` paths too.

Each reading argument is listed below with the bundled example file it reads.
"""

from __future__ import annotations

import json
import re
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Optional

import pytest

import rockmech
from shared_schema.documents.base import Document

EX = rockmech.examples_dir()
WALLS = EX / "constants" / "rect_walls.json"
TABLE = EX / "constants" / "walls.csv"
CHURCH = EX / "constants" / "church_geometry.json"
RECORD = EX / "records" / "elcentro_NS.dat"
SITE = EX / "sites" / "ntc_site.json"
FACADE = EX / "scenes" / "facade.3dm"
FACADE_SPEC = EX / "specs" / "facade.spec.json"
SEARCH_SCENE = EX / "scenes" / "search_facade.3dm"
SEARCH_SPEC = EX / "specs" / "search_facade.search.json"
#: A retrofit spec (none is bundled: its anchorage resistance is the engineer's), written
#: once for the session.
RETROFIT = Path(tempfile.mkdtemp(prefix="rockmech-api-paths-")) / "retrofit.json"
RETROFIT.write_text(
    json.dumps(
        {
            "steel": {"grade": "S275", "diameters_mm": [16, 20, 24]},
            "anchorage": {"capacity_N": 80000, "source": "a test's stated value"},
        }
    ),
    encoding="utf-8",
)
#: The message of a path argument of another type (shared_schema.paths.PATH_TYPES).
NOT_A_PATH = r"must be (a \w+ or )?a path \(str or os\.PathLike"


@dataclass(frozen=True)
class Slot:
    """One path argument of one public function.

    ``call`` calls the function with that argument set and every other as a ``Path``;
    ``field`` is what its errors on a missing file or a folder name (None: the path itself,
    as ``load_constants`` words them); ``type_field`` what an argument of another type
    names (default ``field``); an ``optional`` argument takes None as "not given".
    """

    function: str
    argument: str
    example: Path
    call: Callable[[Any], Any]
    field: Optional[str]
    type_field: Optional[str] = None
    optional: bool = False

    @property
    def id(self) -> str:
        return f"{self.function}:{self.argument}:{self.example.name}"


READERS = [
    Slot("read_constants", "path", WALLS, rockmech.read_constants, "constants"),
    Slot("read_constants", "path", TABLE, rockmech.read_constants, "constants"),
    Slot("load_constants", "path", WALLS, rockmech.load_constants, None, "constants"),
    Slot("constants_from_table", "path", TABLE, rockmech.constants_from_table, "table"),
    Slot(
        "constants_from_scene",
        "scene",
        FACADE,
        lambda p: rockmech.constants_from_scene(p, FACADE_SPEC),
        "scene",
    ),
    Slot(
        "constants_from_scene",
        "spec",
        FACADE_SPEC,
        lambda p: rockmech.constants_from_scene(FACADE, p),
        "spec",
    ),
    Slot(
        "constants_from_files",
        "scene",
        FACADE,
        lambda p: rockmech.constants_from_files(p, FACADE_SPEC),
        "scene",
    ),
    Slot(
        "constants_from_files",
        "spec",
        FACADE_SPEC,
        lambda p: rockmech.constants_from_files(FACADE, p),
        "spec",
    ),
    Slot("load_models", "constants", WALLS, rockmech.load_models, "constants"),
    Slot("read_record", "path", RECORD, rockmech.read_record, "record"),
    Slot("read_site", "path", SITE, rockmech.read_site, "site"),
    Slot("read_scene", "source", FACADE, rockmech.read_scene, "scene"),
    Slot("read_search_spec", "path", SEARCH_SPEC, rockmech.read_search_spec, "spec"),
    Slot(
        "history",
        "constants",
        WALLS,
        lambda p: rockmech.history(p, RECORD, scales=[1.0]),
        "constants",
    ),
    Slot("history", "record", RECORD, lambda p: rockmech.history(WALLS, p, scales=[1.0]), "record"),
    Slot("envelope", "constants", WALLS, lambda p: rockmech.envelope(p, n=3), "constants"),
    Slot(
        "ida",
        "constants",
        WALLS,
        lambda p: rockmech.ida(p, [RECORD], levels=[1.0], jobs=1),
        "constants",
    ),
    Slot(
        "ida",
        "records",
        RECORD,
        lambda p: rockmech.ida(WALLS, [p], levels=[1.0], jobs=1),
        "record",
        "records[0]",
    ),
    Slot("check", "constants", CHURCH, lambda p: rockmech.check(p, SITE), "constants"),
    Slot("check", "site", SITE, lambda p: rockmech.check(CHURCH, p), "site"),
    Slot("assess", "constants", CHURCH, lambda p: rockmech.assess(p, SITE), "constants"),
    Slot("assess", "site", SITE, lambda p: rockmech.assess(CHURCH, p), "site"),
    Slot(
        "retrofit",
        "constants",
        CHURCH,
        lambda p: rockmech.retrofit(p, SITE, RETROFIT),
        "constants",
    ),
    Slot("retrofit", "site", SITE, lambda p: rockmech.retrofit(CHURCH, p, RETROFIT), "site"),
    Slot(
        "retrofit",
        "spec",
        RETROFIT,
        lambda p: rockmech.retrofit(CHURCH, SITE, p),
        "retrofit",
        "spec",
    ),
    Slot("read_retrofit_spec", "path", RETROFIT, rockmech.read_retrofit_spec, "retrofit"),
    Slot(
        "build_report",
        "cf",
        WALLS,
        lambda p: rockmech.build_report(p, [0.5, 1.0]),
        "constants",
        "cf",
    ),
    Slot(
        "search_from_files",
        "scene",
        SEARCH_SCENE,
        lambda p: rockmech.search_from_files(p, SEARCH_SPEC),
        "scene",
    ),
    Slot(
        "search_from_files",
        "spec",
        SEARCH_SPEC,
        lambda p: rockmech.search_from_files(SEARCH_SCENE, p),
        "spec",
    ),
    Slot(
        "search_from_files",
        "site",
        SITE,
        lambda p: rockmech.search_from_files(SEARCH_SCENE, SEARCH_SPEC, site=p),
        "site",
        optional=True,
    ),
    Slot(
        "search_from_files",
        "records",
        RECORD,
        lambda p: rockmech.search_from_files(SEARCH_SCENE, SEARCH_SPEC, records=[p]),
        "record",
        "records[0]",
    ),
]
IDS = [slot.id for slot in READERS]
#: Document keys that hold wall-clock times, which differ between two runs of one analysis.
TIMING_KEYS = {"timings", "runtime_s", "compute_s", "backend"}


def _untimed(doc: Any) -> Any:
    if isinstance(doc, dict):
        return {k: _untimed(v) for k, v in doc.items() if k not in TIMING_KEYS}
    if isinstance(doc, list):
        return [_untimed(v) for v in doc]
    return doc


def canonical(value: Any) -> Any:
    """A comparable form of what a reader returns (JSON text, or plain values)."""
    if isinstance(value, list):
        return [canonical(v) for v in value]
    if isinstance(value, str):  # an HTML report: its minute of writing aside
        return re.sub(r"generated [^<]*? UTC", "generated", value)
    if isinstance(value, rockmech.GroundMotion):
        return (value.name, value.dt, value.accel.acc.tolist(), value.warnings, value.metadata)
    if isinstance(value, Document):  # the analyses' documents: their JSON, clocks aside
        return json.dumps(_untimed(value.to_dict()), sort_keys=True)
    if hasattr(value, "model_dump"):  # ConstantsFile, SiteFile, SearchSpec
        return json.dumps(value.model_dump(mode="json"), sort_keys=True)
    if hasattr(value, "doc"):  # the IDA's result and SearchRun
        return json.dumps(_untimed(value.doc), sort_keys=True)
    if hasattr(value, "objects"):  # a scene
        return (value.units, value.unit_scale, value.tolerance, value.objects)
    return value  # RockingModel: a dataclass of numbers


def test_every_reader_of_the_api_page_is_listed() -> None:
    """The list above covers every function docs/api.md shows reading a file."""
    page = (Path(__file__).resolve().parents[1] / "docs" / "api.md").read_text(encoding="utf-8")
    shown = set(re.findall(r"rockmech\.(\w+)\(ex /", page))
    shown |= set(re.findall(r"rockmech\.(\w+)\(\s*ex /", page))
    assert shown, "docs/api.md shows no call on a bundled file"
    assert shown <= {slot.function for slot in READERS}, shown - {s.function for s in READERS}


@pytest.mark.parametrize("slot", READERS, ids=IDS)
def test_a_str_path_reads_as_a_path_object_does(slot: Slot) -> None:
    assert slot.example.is_file()
    from_path = slot.call(slot.example)
    from_str = slot.call(str(slot.example))
    assert canonical(from_str) == canonical(from_path)


def _named(slot: Slot, path: Path, exc: rockmech.InputError) -> None:
    assert str(path) in str(exc), str(exc)
    assert exc.field == (str(path) if slot.field is None else slot.field), str(exc)


@pytest.mark.parametrize("kind", [str, Path])
@pytest.mark.parametrize("slot", READERS, ids=IDS)
def test_a_missing_file_is_an_input_error_naming_the_path(
    slot: Slot, kind: type, tmp_path: Path
) -> None:
    missing = tmp_path / "no such folder" / slot.example.name
    with pytest.raises(rockmech.InputError, match="file not found") as info:
        slot.call(kind(missing))
    _named(slot, missing, info.value)


@pytest.mark.parametrize("kind", [str, Path])
@pytest.mark.parametrize("slot", READERS, ids=IDS)
def test_a_folder_is_an_input_error_saying_so(slot: Slot, kind: type, tmp_path: Path) -> None:
    folder = tmp_path / slot.example.name  # a folder with a file's name and suffix
    folder.mkdir()
    with pytest.raises(rockmech.InputError, match="is a folder, not a") as info:
        slot.call(kind(folder))
    _named(slot, folder, info.value)


@pytest.mark.parametrize(
    ("value", "what"),
    [
        (3, "got int"),
        (None, "got NoneType"),
        (b"examples/constants/rect_walls.json", r"got bytes; decode a bytes path first"),
        ("", "got an empty string"),
    ],
    ids=["int", "None", "bytes", "empty"],
)
@pytest.mark.parametrize("slot", READERS, ids=IDS)
def test_an_argument_that_is_no_path_is_an_input_error_naming_it(
    slot: Slot, value: Any, what: str
) -> None:
    if slot.function == "read_scene" and isinstance(value, bytes):
        pytest.skip("read_scene reads bytes as the file's content (tests/cad/test_scene_mesh.py)")
    if slot.optional and value is None:
        pytest.skip(f"{slot.argument}=None is the default: not given")
    with pytest.raises(rockmech.InputError, match=NOT_A_PATH + r".*" + what) as info:
        slot.call(value)
    assert info.value.field == (slot.type_field or slot.field)


@pytest.mark.parametrize("slot", READERS[:3], ids=IDS[:3])
def test_an_open_file_is_refused_with_its_path_asked_for(slot: Slot) -> None:
    with slot.example.open("rb") as handle:
        with pytest.raises(rockmech.InputError, match=r"got an open file .*pass the file's path"):
            slot.call(handle)


def test_a_single_record_where_a_list_belongs_is_refused() -> None:
    # a str is a sequence of characters: without the check each would be read as a file
    with pytest.raises(rockmech.InputError, match=r"^records: .*got one record; give a list"):
        rockmech.ida(WALLS, str(RECORD), levels=[1.0], jobs=1)  # type: ignore[arg-type]
    with pytest.raises(rockmech.InputError, match=r"^records: .*got one record"):
        rockmech.search_from_files(SEARCH_SCENE, SEARCH_SPEC, records=str(RECORD))


# The writers: a str target writes what a Path target writes.


def test_writers_take_str_targets(tmp_path: Path) -> None:
    cf = rockmech.read_constants(WALLS)
    rockmech.save_constants(str(tmp_path / "a.json"), cf)
    rockmech.save_constants(tmp_path / "b.json", cf)
    assert (tmp_path / "a.json").read_bytes() == (tmp_path / "b.json").read_bytes()
    again = rockmech.read_constants(tmp_path / "a.json")  # stamped with rockmech's version
    assert again.model_dump(exclude={"rockmech_version"}) == cf.model_dump(
        exclude={"rockmech_version"}
    )

    page = rockmech.build_report(cf, [0.5, 1.0])
    assert rockmech.write_report(str(tmp_path / "r.html"), page) == tmp_path / "r.html"
    assert (tmp_path / "r.html").read_text(encoding="utf-8") == page

    written = rockmech.copy_examples(str(tmp_path / "ex"))
    assert tmp_path / "ex" / "constants" / "rect_walls.json" in written
    assert (tmp_path / "ex" / "constants" / "rect_walls.json").read_bytes() == WALLS.read_bytes()


def test_writers_refuse_a_folder_for_a_file_and_a_non_path(tmp_path: Path) -> None:
    cf = rockmech.read_constants(WALLS)
    with pytest.raises(
        rockmech.InputError, match="cannot write constants file: it is a folder"
    ) as info:
        rockmech.save_constants(str(tmp_path), cf)
    assert info.value.field == str(tmp_path)
    with pytest.raises(rockmech.InputError, match=r"^path: is a folder, not a file: "):
        rockmech.write_report(str(tmp_path), "<html></html>")
    with pytest.raises(rockmech.InputError, match=r"^path: " + NOT_A_PATH):
        rockmech.save_constants(3, cf)  # type: ignore[arg-type]
    with pytest.raises(rockmech.InputError, match=r"^dest: " + NOT_A_PATH):
        rockmech.copy_examples(None)  # type: ignore[arg-type]


# search_run: objects already read, a dict spec validated as a file is.


@pytest.fixture(scope="module")
def search_inputs() -> tuple[Any, Any, dict[str, Any]]:
    scene = rockmech.read_scene(SEARCH_SCENE)
    spec = rockmech.read_search_spec(SEARCH_SPEC)
    raw = json.loads(SEARCH_SPEC.read_text(encoding="utf-8"))
    return scene, spec, raw


def test_search_run_takes_a_dict_spec_as_the_spec_it_reads(search_inputs: Any) -> None:
    scene, spec, raw = search_inputs
    from_spec = rockmech.search_run(scene, spec, spec_dir=SEARCH_SPEC.parent)
    from_dict = rockmech.search_run(scene, raw, spec_dir=str(SEARCH_SPEC.parent))
    assert canonical(from_dict) == canonical(from_spec)


def test_search_run_says_what_it_takes(search_inputs: Any) -> None:
    scene, spec, raw = search_inputs
    with pytest.raises(rockmech.InputError, match=r"^spec: must be a SearchSpec or a dict"):
        rockmech.search_run(scene, 42)  # type: ignore[arg-type]
    with pytest.raises(rockmech.InputError, match=r"rockmech\.read_search_spec\(path\)"):
        rockmech.search_run(scene, str(SEARCH_SPEC))  # type: ignore[arg-type]
    with pytest.raises(rockmech.InputError, match=r"^scene: must be a scene .*read_scene\(path\)"):
        rockmech.search_run(str(SEARCH_SCENE), spec)
    bad = dict(raw, friction="high")
    with pytest.raises(rockmech.InputError, match=r"^mine: friction: ") as info:
        rockmech.search_run(scene, bad, spec_name="mine", spec_dir=SEARCH_SPEC.parent)
    assert info.value.field == "mine"
    with pytest.raises(rockmech.InputError, match=r"^spec: a spec given as a dict holds JSON"):
        rockmech.search_run(scene, dict(raw, friction=object()))
