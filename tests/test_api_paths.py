"""Paths the Python way in the public API, for every public function (#38).

Every function of ``rockmech.__all__`` is listed below: each argument that reads a file (a
``Slot``), each that writes one (a ``Target``), each that names a folder files are read from
(``FOLDERS``), or, for a function that takes no path, the reason (``NO_PATH``). A test checks
that the lists cover ``rockmech.__all__`` and every path-typed parameter of each signature,
so a new function or argument cannot escape them.

A reading argument takes the path as a ``str`` or a ``pathlib.Path`` and gives the same
result for both; a missing file, a folder, or an argument that is not a path (bytes, an open
file, a number) is a ``rockmech.InputError`` naming the argument and, for a file, the path:
never an ``AttributeError`` or a ``TypeError`` from inside a reader. A writing argument takes
``str`` and ``Path`` alike and refuses a folder for a file, a file for a folder and a
non-path, naming the argument.
"""

from __future__ import annotations

import functools
import inspect
import io
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
NOT_A_PATH = r"must be (a [^;]+? or )?a path \(str or os\.PathLike"
#: The public functions: every callable of rockmech.__all__ that is not a class.
FUNCTIONS = sorted(
    name
    for name in rockmech.__all__
    if name != "__version__"
    and callable(getattr(rockmech, name))
    and not inspect.isclass(getattr(rockmech, name))
)
#: An annotation that admits a path (the analyses' ``Constants`` and ``Record`` do).
PATH_ANNOTATION = re.compile(r"PathLike|\bPath\b|\bConstants\b|\bRecord\b")


@dataclass(frozen=True)
class Slot:
    """One path argument of one public function.

    ``call`` calls the function with that argument set and every other as a ``Path``;
    ``field`` is what its errors on a missing file or a folder name; ``type_field`` what an
    argument of another type names (default ``field``); an ``optional`` argument takes None
    as "not given".
    """

    function: str
    argument: str
    example: Path
    call: Callable[[Any], Any]
    field: str
    type_field: Optional[str] = None
    optional: bool = False

    @property
    def id(self) -> str:
        return f"{self.function}:{self.argument}:{self.example.name}"


READERS = [
    Slot("read_constants", "path", WALLS, rockmech.read_constants, "constants"),
    Slot("read_constants", "path", TABLE, rockmech.read_constants, "constants"),
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
        "models_from_constants",
        "constants",
        WALLS,
        rockmech.models_from_constants,
        "constants",
    ),
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
        "assess",
        "records",
        RECORD,
        lambda p: rockmech.assess(CHURCH, SITE, [p], multiples=[1.0]),
        "record",
        "records[0]",
    ),
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
    Slot(
        "retrofit",
        "records",
        RECORD,
        lambda p: rockmech.retrofit(CHURCH, SITE, RETROFIT, [p]),
        "record",
        "records[0]",
    ),
    Slot("read_retrofit_spec", "path", RETROFIT, rockmech.read_retrofit_spec, "retrofit"),
    Slot(
        "build_report",
        "constants",
        WALLS,
        lambda p: rockmech.build_report(p, [0.5, 1.0]),
        "constants",
    ),
    Slot(
        "build_report",
        "motion",
        RECORD,
        lambda p: rockmech.build_report(WALLS, [1.0], motion=p),
        "record",
        "motion",
        optional=True,
    ),
    Slot("search", "scene", SEARCH_SCENE, lambda p: rockmech.search(p, SEARCH_SPEC), "scene"),
    Slot("search", "spec", SEARCH_SPEC, lambda p: rockmech.search(SEARCH_SCENE, p), "spec"),
    Slot(
        "search",
        "site",
        SITE,
        lambda p: rockmech.search(SEARCH_SCENE, SEARCH_SPEC, site=p),
        "site",
        optional=True,
    ),
    Slot(
        "search",
        "records",
        RECORD,
        lambda p: rockmech.search(SEARCH_SCENE, SEARCH_SPEC, records=[p]),
        "record",
        "records[0]",
    ),
]
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
    if hasattr(value, "doc"):  # SearchRun (its SearchDocument)
        return json.dumps(_untimed(value.doc.to_dict()), sort_keys=True)
    if hasattr(value, "objects"):  # a scene
        return (value.units, value.unit_scale, value.tolerance, value.objects)
    return value  # RockingModel: a dataclass of numbers


@dataclass(frozen=True)
class Target:
    """One argument of a public function that names where to write (a file or a folder).

    ``call`` writes to the target given and returns what the function wrote, for
    comparison; a ``folder`` target is a folder (created if missing), else a file;
    ``makes_parents``: a file target's missing folder is created (else refused).
    """

    function: str
    argument: str
    call: Callable[[Any], Any]
    folder: bool
    makes_parents: bool = True

    @property
    def id(self) -> str:
        return f"{self.function}:{self.argument}"


@pytest.fixture(scope="module")
def walls() -> Any:
    return rockmech.read_constants(WALLS)


@pytest.fixture(scope="module")
def search_inputs() -> tuple[Any, Any, dict[str, Any]]:
    scene = rockmech.read_scene(SEARCH_SCENE)
    spec = rockmech.read_search_spec(SEARCH_SPEC)
    raw = json.loads(SEARCH_SPEC.read_text(encoding="utf-8"))
    return scene, spec, raw


def _files(folder: Path) -> dict[str, bytes]:
    return {
        str(p.relative_to(folder)): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file() and ".rockmech" not in p.parts
    }


_CF = rockmech.read_constants(WALLS)
_PAGE = "<!DOCTYPE html>\n<html><body>a report</body></html>\n"


def _search_files(out: Any) -> dict[str, bytes]:
    rockmech.write_search(_search_run(), out, figure=False)
    files = _files(Path(out))
    files.pop("search.3dm")  # a .3dm file stamps the minute it was written
    return files


@functools.cache
def _search_run() -> Any:
    """One search for the writers' tests, which compare two writes of it (no records: quick)."""
    return rockmech.search(SEARCH_SCENE, SEARCH_SPEC, records=[])


TARGETS = [
    Target(
        "write_constants",
        "path",
        lambda p: (rockmech.write_constants(_CF, p), Path(p).read_bytes())[1],
        folder=False,
        makes_parents=False,
    ),
    Target(
        "write_report",
        "path",
        lambda p: (rockmech.write_report(_PAGE, p), Path(p).read_bytes())[1],
        folder=False,
    ),
    Target("write_search", "out", _search_files, folder=True),
    Target("copy_examples", "out", lambda p: (rockmech.copy_examples(p), _files(Path(p)))[1], True),
]
#: Arguments that name a folder files are read from: (function, argument).
FOLDERS = [("search", "spec_dir")]
#: The public functions that take no path, and what they take instead.
NO_PATH = {
    "pulse": "a RockingModel and the pulse's numbers",
    "solve_pulse": "a request (a PulseRequest or a dict)",
    "simulate": "a RockingModel and an excitation object",
    "simulate_batch": "RockingModels and an excitation object",
    "mechanism_envelope": "a RockingModel and frequencies",
    "critical_bands": "envelopes",
    "extract_pulses": "a sampled acceleration (GroundMotion.accel)",
    "largest_pulse": "a sampled acceleration (GroundMotion.accel)",
    "response_spectrum": "an acceleration array and its time step",
    "examples_dir": "nothing: it returns the bundled examples' folder",
    "kernel_status": "nothing",
}
IDS = [slot.id for slot in READERS]
#: Functions whose whole run (a search of the façade: seconds each) the str-and-Path and
#: open-file comparisons mark slow: the quick loop keeps their refusals and
#: test_search_takes_objects_as_it_takes_files; the whole suite (CI) runs them all.
HEAVY = frozenset({"search"})


def _runs(slots: list[Slot]) -> list[Any]:
    """The slots as parameters, those of HEAVY functions marked slow."""
    return [
        pytest.param(s, id=s.id, marks=[pytest.mark.slow] if s.function in HEAVY else [])
        for s in slots
    ]


TARGET_IDS = [target.id for target in TARGETS]


def _path_parameters(name: str) -> set[str]:
    parameters = inspect.signature(getattr(rockmech, name)).parameters.values()
    return {p.name for p in parameters if PATH_ANNOTATION.search(str(p.annotation))}


def test_every_public_function_is_listed_with_its_path_arguments() -> None:
    """Each function of rockmech.__all__ is a reader, a writer, or takes no path."""
    assert len(FUNCTIONS) >= 30
    listed = {slot.function for slot in READERS} | {t.function for t in TARGETS}
    listed |= {function for function, _ in FOLDERS}
    assert not listed & set(NO_PATH), listed & set(NO_PATH)
    assert sorted(listed | set(NO_PATH)) == FUNCTIONS, (
        "unlisted: " + str(set(FUNCTIONS) - listed - set(NO_PATH)),
        "not public: " + str((listed | set(NO_PATH)) - set(FUNCTIONS)),
    )
    arguments = {(s.function, s.argument) for s in READERS} | {
        (t.function, t.argument) for t in TARGETS
    }
    arguments |= set(FOLDERS)
    for function, argument in arguments:  # each listed argument is in the signature
        assert argument in inspect.signature(getattr(rockmech, function)).parameters, (
            function,
            argument,
        )
    for name in FUNCTIONS:  # and each argument typed as a path is listed
        missing = {a for a in _path_parameters(name) if (name, a) not in arguments}
        assert not missing, f"{name}: path arguments {missing} have no Slot or Target"
    for name in NO_PATH:
        assert not _path_parameters(name), name


def test_every_reader_of_the_api_page_is_listed() -> None:
    """The list above covers every function docs/api.md shows reading a file."""
    page = (Path(__file__).resolve().parents[1] / "docs" / "api.md").read_text(encoding="utf-8")
    shown = set(re.findall(r"rockmech\.(\w+)\(\s*ex /", page))
    assert shown, "docs/api.md shows no call on a bundled file"
    assert shown <= {slot.function for slot in READERS}, shown - {s.function for s in READERS}


@pytest.mark.parametrize("slot", _runs(READERS))
def test_a_str_path_reads_as_a_path_object_does(slot: Slot) -> None:
    assert slot.example.is_file()
    from_path = slot.call(slot.example)
    from_str = slot.call(str(slot.example))
    assert canonical(from_str) == canonical(from_path)


def _named(slot: Slot, path: Path, exc: rockmech.InputError) -> None:
    assert str(path) in str(exc), str(exc)
    assert exc.field == slot.field, str(exc)


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


def _takes_open_files(slot: Slot) -> bool:
    """A JSON document (constants, a site, a retrofit or search spec) is read from an open file."""
    parameter = inspect.signature(getattr(rockmech, slot.function)).parameters[slot.argument]
    typed = re.search(r"\b(Source|Constants|Site)\b|\bIO\[", str(parameter.annotation))
    return typed is not None and slot.example.suffix == ".json"


OPEN_FILE_READERS = [slot for slot in READERS if _takes_open_files(slot)]
PATH_ONLY_READERS = [slot for slot in READERS if not _takes_open_files(slot)]


def test_the_open_file_readers_are_the_json_documents() -> None:
    documents = {(s.function, s.argument) for s in OPEN_FILE_READERS}
    assert {
        ("read_constants", "path"),
        ("read_site", "path"),
        ("read_search_spec", "path"),
        ("read_retrofit_spec", "path"),
        ("check", "site"),
        ("retrofit", "spec"),
        ("search", "spec"),
    } <= documents
    assert ("read_record", "path") not in documents and ("read_scene", "source") not in documents


@pytest.mark.parametrize("mode", ["rb", "r", "bytesio"])
@pytest.mark.parametrize("slot", _runs(OPEN_FILE_READERS))
def test_an_open_file_reads_as_its_path_does(slot: Slot, mode: str) -> None:
    if slot.function == "search" and slot.argument == "spec":
        pytest.skip("an open spec has no folder: test_search_reads_an_open_spec_with_its_folder")
    want = canonical(slot.call(slot.example))
    if mode == "bytesio":
        got = slot.call(io.BytesIO(slot.example.read_bytes()))
    else:
        with slot.example.open(mode, encoding=None if mode == "rb" else "utf-8") as handle:
            got = slot.call(handle)
    assert canonical(got) == want


def test_search_reads_an_open_spec_with_its_folder() -> None:
    with SEARCH_SPEC.open("rb") as handle:
        run = rockmech.search(SEARCH_SCENE, handle, spec_dir=SEARCH_SPEC.parent)
    assert canonical(run) == canonical(rockmech.search(SEARCH_SCENE, SEARCH_SPEC))
    with SEARCH_SPEC.open("rb") as handle:  # the spec names its site relative to its folder
        with pytest.raises(rockmech.InputError, match=r"^ranking\.site: .*not found"):
            rockmech.search(SEARCH_SCENE, handle)


@pytest.mark.parametrize("slot", PATH_ONLY_READERS, ids=[s.id for s in PATH_ONLY_READERS])
def test_an_open_file_where_a_path_belongs_is_refused(slot: Slot) -> None:
    with slot.example.open("rb") as handle:
        with pytest.raises(rockmech.InputError) as info:
            slot.call(handle)
    assert re.search(r"open file\b.*pass the (file's )?path", str(info.value)), str(info.value)


def test_an_open_file_that_cannot_be_read_is_an_input_error_naming_it(tmp_path: Path) -> None:
    with SITE.open("rb") as handle:
        pass  # closed
    with pytest.raises(rockmech.InputError, match=r"^site: cannot be read: ntc_site\.json: "):
        rockmech.read_site(handle)
    with (tmp_path / "w.json").open("wb") as handle:
        with pytest.raises(rockmech.InputError, match=r"^constants: cannot be read: w\.json"):
            rockmech.read_constants(handle)
    with pytest.raises(rockmech.InputError, match=r"^site: <open file> is empty"):
        rockmech.read_site(io.BytesIO(b""))


def test_a_single_record_where_a_list_belongs_is_refused() -> None:
    # a str is a sequence of characters: without the check each would be read as a file
    with pytest.raises(rockmech.InputError, match=r"^records: .*got one record; give a list"):
        rockmech.ida(WALLS, str(RECORD), levels=[1.0], jobs=1)  # type: ignore[arg-type]
    with pytest.raises(rockmech.InputError, match=r"^records: .*got one record"):
        rockmech.search(SEARCH_SCENE, SEARCH_SPEC, records=str(RECORD))


# The writers: a str target writes what a Path target writes; a folder for a file, a file for
# a folder and a non-path are refused, naming the argument.


@pytest.mark.parametrize("target", TARGETS, ids=TARGET_IDS)
def test_a_str_target_writes_what_a_path_target_writes(target: Target, tmp_path: Path) -> None:
    name = "out" if target.folder else "out.file"
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    by_str = target.call(str(tmp_path / "a" / name))
    by_path = target.call(tmp_path / "b" / name)
    assert by_str  # something was written
    assert by_str == by_path


@pytest.mark.parametrize("kind", [str, Path])
@pytest.mark.parametrize("target", TARGETS, ids=TARGET_IDS)
def test_a_target_of_the_wrong_kind_is_an_input_error_naming_it(
    target: Target, kind: type, tmp_path: Path
) -> None:
    if target.folder:  # a file where the folder belongs
        wrong = tmp_path / "a file"
        wrong.write_text("the user's own file\n")
    else:  # a folder where the file belongs
        wrong = tmp_path / "out.json"
        wrong.mkdir()
    with pytest.raises(rockmech.InputError) as info:
        target.call(kind(wrong))
    assert info.value.field == target.argument, str(info.value)
    assert str(wrong) in str(info.value)
    if target.folder:
        assert wrong.read_text() == "the user's own file\n"


@pytest.mark.parametrize("kind", [str, Path])
@pytest.mark.parametrize("target", TARGETS, ids=TARGET_IDS)
def test_a_missing_folder_is_made_or_named(target: Target, kind: type, tmp_path: Path) -> None:
    missing = tmp_path / "no such folder" / ("out" if target.folder else "out.file")
    if target.makes_parents or target.folder:
        assert target.call(kind(missing))
        assert missing.exists()
    else:
        with pytest.raises(rockmech.InputError, match="No such file or directory") as info:
            target.call(kind(missing))
        assert info.value.field == target.argument and str(missing) in str(info.value)


@pytest.mark.parametrize("value", [3, None, b"out", ""], ids=["int", "None", "bytes", "empty"])
@pytest.mark.parametrize("target", TARGETS, ids=TARGET_IDS)
def test_a_target_that_is_no_path_is_an_input_error_naming_it(target: Target, value: Any) -> None:
    with pytest.raises(rockmech.InputError, match=r"^\w+: " + NOT_A_PATH) as info:
        target.call(value)
    assert info.value.field == target.argument


def test_the_object_comes_first_and_the_path_second(tmp_path: Path) -> None:
    page = tmp_path / "r.html"
    with pytest.raises(rockmech.InputError, match=r"^constants: .*come first: write_constants"):
        rockmech.write_constants(str(tmp_path / "c.json"), _CF)  # type: ignore[arg-type]
    with pytest.raises(rockmech.InputError, match=r"^path: looks like an HTML page"):
        rockmech.write_report(str(page), _PAGE)
    with pytest.raises(rockmech.InputError, match=r"^page: must be the HTML page"):
        rockmech.write_report(page, page)  # type: ignore[arg-type]
    assert list(tmp_path.iterdir()) == []  # nothing written


def test_the_report_page_is_written_as_built(walls: Any, tmp_path: Path) -> None:
    page = rockmech.build_report(walls, [0.5, 1.0])
    assert rockmech.write_report(page, str(tmp_path / "r.html")) == tmp_path / "r.html"
    assert (tmp_path / "r.html").read_text(encoding="utf-8") == page
    again = rockmech.write_constants(walls, tmp_path / "c.json")
    assert again is None
    back = rockmech.read_constants(tmp_path / "c.json")  # stamped with rockmech's version
    assert back.model_dump(exclude={"rockmech_version"}) == walls.model_dump(
        exclude={"rockmech_version"}
    )


# A folder files are read from: the search spec's folder.


@pytest.mark.parametrize("kind", [str, Path])
def test_a_spec_folder_is_a_folder(kind: type, search_inputs: Any, tmp_path: Path) -> None:
    scene, spec, _ = search_inputs
    missing = tmp_path / "no such folder"
    with pytest.raises(rockmech.InputError, match=r"^spec_dir: folder not found: ") as info:
        rockmech.search(scene, spec, spec_dir=kind(missing))
    assert str(missing) in str(info.value)
    with pytest.raises(rockmech.InputError, match=r"^spec_dir: is a file, not a folder: "):
        rockmech.search(scene, spec, spec_dir=kind(SEARCH_SPEC))
    with pytest.raises(rockmech.InputError, match=r"^spec_dir: " + NOT_A_PATH):
        rockmech.search(scene, spec, spec_dir=3)  # type: ignore[arg-type]


# search: files or objects already read, a dict spec validated as a file is.


def _provenance_aside(run: Any) -> Any:
    doc = run.doc.to_dict()
    doc.pop("input")  # the names of the scene and the spec, as given
    return json.dumps(_untimed(doc), sort_keys=True)


def test_search_takes_objects_as_it_takes_files(search_inputs: Any) -> None:
    scene, spec, raw = search_inputs
    from_files = rockmech.search(str(SEARCH_SCENE), SEARCH_SPEC)
    from_spec = rockmech.search(scene, spec, spec_dir=SEARCH_SPEC.parent)
    from_dict = rockmech.search(scene, raw, spec_dir=str(SEARCH_SPEC.parent))
    assert canonical(from_dict) == canonical(from_spec)
    assert _provenance_aside(from_files) == _provenance_aside(from_spec)
    assert from_files.doc.input.scene != from_spec.doc.input.scene  # its name


def test_search_says_what_it_takes(search_inputs: Any) -> None:
    scene, spec, raw = search_inputs
    with pytest.raises(
        rockmech.InputError, match=r"^spec: must be a SearchSpec, a dict of its fields or a path"
    ):
        rockmech.search(scene, 42)  # type: ignore[arg-type]
    with pytest.raises(rockmech.InputError, match=r"^scene: must be a scene .*or a path"):
        rockmech.search(42, spec)  # type: ignore[arg-type]
    with pytest.raises(rockmech.InputError, match=r"^units: applies to a scene file"):
        rockmech.search(scene, spec, units="m")
    bad = dict(raw, friction="high")
    with pytest.raises(rockmech.InputError, match=r"^search spec: friction: ") as info:
        rockmech.search(scene, bad, spec_dir=SEARCH_SPEC.parent)
    assert info.value.field == "search spec"
    with pytest.raises(rockmech.InputError, match=r"^spec: a spec given as a dict holds JSON"):
        rockmech.search(scene, dict(raw, friction=object()))


def test_the_ida_intensity_measure_has_one_name() -> None:
    """``measure`` in, ``measure`` out; a PGA level [g] is the scale factor level / PGA."""
    pga_g = rockmech.read_record(RECORD).pga_g
    by_pga = rockmech.ida(WALLS, [RECORD], levels=[0.1, 0.3], measure="pga", jobs=1)
    assert by_pga.measure == "pga" == by_pga.to_dict()["intensity"]["measure"]
    assert by_pga.intensity.units == "g" and by_pga.levels == [0.1, 0.3]
    scales = [0.1 / pga_g, 0.3 / pga_g]
    by_scale = rockmech.ida(WALLS, [RECORD], levels=scales, measure="scale", jobs=1)
    assert by_scale.measure == "scale"
    fractions = {m.id: by_pga.find(m.id).fraction for m in by_pga.mechanisms}
    assert fractions == {m.id: by_scale.find(m.id).fraction for m in by_scale.mechanisms}
    assert 0.0 in fractions["F1"] or 1.0 in fractions["W1"]  # not all the same verdict
    with pytest.raises(rockmech.InputError, match=r"^measure: must be one of \['scale', 'pga'\]"):
        rockmech.ida(WALLS, [RECORD], levels=[1.0], measure="pgv", jobs=1)
    with pytest.raises(TypeError, match="'im'"):
        rockmech.ida(WALLS, [RECORD], levels=[1.0], im="pga")  # type: ignore[call-arg]


# Arguments of another type, for the functions that take no path: an InputError naming the
# argument, saying what it takes and, where there is one, how to get it from what was given.


def _motion() -> Any:
    return rockmech.read_record(RECORD)


def _model() -> Any:
    return rockmech.models_from_constants(_CF)[0]


WRONG_TYPES: dict[str, list[tuple[Callable[[], Any], str, str]]] = {
    "pulse": [
        (lambda: rockmech.pulse(_CF, 0.3, 1.0), "model", r"got ConstantsFile; .*models_from_const"),
        (lambda: rockmech.pulse("W1", 0.3, 1.0), "model", r"got str; build one with"),
    ],
    "simulate": [
        (lambda: rockmech.simulate(_model(), _motion()), "excitation", r"its \.accel"),
        (lambda: rockmech.simulate(_model(), str(RECORD)), "excitation", r"read_record\(path\)"),
        (lambda: rockmech.simulate(_CF.mechanisms[0], _motion().accel), "model", "Mechanism"),
    ],
    "simulate_batch": [
        (lambda: rockmech.simulate_batch(_model(), _motion().accel, [1.0]), "models", r"\[model\]"),
        (lambda: rockmech.simulate_batch([_CF], _motion().accel, [1.0]), "models[0]", "Constants"),
    ],
    "solve_pulse": [(lambda: rockmech.solve_pulse("p_eq=2"), "request", r"a dict of its fields")],
    "mechanism_envelope": [
        (lambda: rockmech.mechanism_envelope(_CF, [1.0]), "model", r"models_from_constants"),
    ],
    "critical_bands": [
        (lambda: rockmech.critical_bands("W1"), "envelopes", r"sequence of Envelopes, got str"),
        (lambda: rockmech.critical_bands([_model()]), "envelopes[0]", r"mechanism_envelope\("),
        (
            lambda: rockmech.critical_bands(rockmech.mechanism_envelope(_model(), [1.0])),
            "envelopes",
            r"\[envelope\]",
        ),
    ],
    "extract_pulses": [(lambda: rockmech.extract_pulses(_motion()), "accel", r"its \.accel")],
    "largest_pulse": [(lambda: rockmech.largest_pulse(str(RECORD)), "accel", r"read_record")],
    "response_spectrum": [
        (lambda: rockmech.response_spectrum("acc", 0.02, [1.0]), "acc", r"must be numbers"),
    ],
}
#: Functions of NO_PATH without arguments to get wrong.
NO_ARGUMENTS = {"examples_dir", "kernel_status"}
CASES = [(name, k) for name, cases in WRONG_TYPES.items() for k in range(len(cases))]


def test_every_function_without_a_path_has_its_wrong_types_tried() -> None:
    assert set(WRONG_TYPES) | NO_ARGUMENTS == set(NO_PATH)
    for name in NO_ARGUMENTS:
        assert not inspect.signature(getattr(rockmech, name)).parameters, name


@pytest.mark.parametrize(("name", "k"), CASES, ids=[f"{n}-{k}" for n, k in CASES])
def test_an_argument_of_another_type_is_an_input_error_saying_what_it_takes(
    name: str, k: int
) -> None:
    call, field, words = WRONG_TYPES[name][k]
    with pytest.raises(rockmech.InputError, match=words) as info:
        call()
    assert info.value.field == field, str(info.value)


@pytest.mark.parametrize(
    ("call", "field", "words"),
    [
        (lambda: rockmech.history(WALLS, RECORD, scales=1.0), "scales", r"\[1\.0\]"),
        (lambda: rockmech.history(WALLS, RECORD, scales=["a"]), "scales[0]", "a number"),
        (lambda: rockmech.ida(WALLS, [RECORD], levels="1,2"), "levels", "got str"),
        (lambda: rockmech.assess(CHURCH, SITE, multiples=2), "multiples", r"\[2\]"),
        (lambda: rockmech.write_search("run", "out"), "run", r"rockmech\.search\("),
    ],
    ids=["scales-number", "scales-str", "levels-str", "multiples-number", "write_search-run"],
)
def test_numbers_and_runs_of_another_type_are_refused(
    call: Callable[[], Any], field: str, words: str
) -> None:
    with pytest.raises(rockmech.InputError, match=words) as info:
        call()
    assert info.value.field == field, str(info.value)
