"""Static checks of the Rhino glue: component contract, script headers, pyright, Python 3.9.

What Rhino runs cannot run here, so these check it as far as possible without Rhino:
- every Grasshopper component folder: class name = folder name, ``RunScript`` parameters =
  metadata inputs, returned values = metadata outputs, a 24 x 24 PNG icon, the headers;
- every command script: ``#! python3``, the ``# venv:`` line and the pinned ``# r:`` line;
- pyright against RhinoCommon (``rhino-stubs-typed``), where pyright and node are present;
- the modules Rhino imports parse as Python 3.9, pass ruff's 3.9 rules, and import and
  compute constants under a real Python 3.9 when one with the dependencies is found.
"""

import ast
import json
import os
import shutil
import struct
import subprocess
import sys
from pathlib import Path
from typing import Any, List, Optional

import pytest

ROOT = Path(__file__).resolve().parents[2]
COMPONENTS = sorted(p for p in (ROOT / "rhino_plugin" / "components").iterdir() if p.is_dir())
SCRIPTS = sorted((ROOT / "rhino_plugin" / "rhino").glob("RM_*.py"))
#: Packages Rhino imports (the glue itself, rhino_plugin.rhino, needs RhinoCommon).
RHINO_IMPORTED = [
    ROOT / "shared_schema",
    ROOT / "cad_maths",
    ROOT / "rhino_plugin" / "flows",
    ROOT / "rhino_plugin" / "__init__.py",
]
COMMANDS = [
    "RM_Analyse",
    "RM_LoadedWall",
    "RM_MultiBlock",
    "RM_Retrofit",
    "RM_Search",
    "RM_SingleBlock",
    "RM_TwoBlock",
]


def _headers(path: Path) -> List[str]:
    return path.read_text(encoding="utf-8").splitlines()[:3]


def _requirements(line: str) -> List[str]:
    assert line.startswith("# r: "), line
    return [r.strip() for r in line[len("# r: ") :].split(",")]


def test_every_command_has_a_script() -> None:
    assert [p.stem for p in SCRIPTS] == COMMANDS


@pytest.mark.parametrize("path", SCRIPTS + [c / "code.py" for c in COMPONENTS], ids=str)
def test_rhino_script_headers_are_present_and_pinned(path: Path) -> None:
    first, venv, req = _headers(path)
    assert first == "#! python3"
    assert venv == "# venv: rockmech"
    reqs = _requirements(req)
    assert reqs, "empty # r: line"
    for r in reqs:
        name, sep, version = r.partition("==")
        assert sep and name and version and version[0].isdigit(), f"{r!r} is not pinned"
    # one environment for every script: the same pins everywhere
    assert req == _headers(SCRIPTS[0])[2]


def test_pins_run_on_python_39() -> None:
    """The pinned versions are ones that support CPython 3.9 (trimesh <= 4.12, numpy < 2.1)."""
    pins = dict(r.split("==") for r in _requirements(_headers(SCRIPTS[0])[2]))
    major_minor = lambda v: tuple(int(x) for x in v.split(".")[:2])  # noqa: E731
    assert major_minor(pins["trimesh"]) <= (4, 12)
    assert major_minor(pins["numpy"]) <= (2, 0)
    assert major_minor(pins["scipy"]) <= (1, 13)
    assert major_minor(pins["matplotlib"]) <= (3, 9)
    assert "rhino3dm" not in pins  # no CPython 3.9 wheel for macOS; Rhino has RhinoCommon


def _png_size(path: Path) -> Any:
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", f"{path} is not a PNG"
    return struct.unpack(">II", data[16:24])


@pytest.mark.parametrize("folder", COMPONENTS, ids=lambda p: p.name)
def test_component_contract(folder: Path) -> None:
    assert folder.name.startswith("RM_")
    meta = json.loads((folder / "metadata.json").read_text(encoding="utf-8"))
    for key in ("name", "nickname", "category", "subcategory", "description"):
        assert meta.get(key), f"metadata.json has no {key}"
    assert meta["category"] == "rockmech"
    inputs = [p["name"] for p in meta["ghpython"]["inputParameters"]]
    outputs = [p["name"] for p in meta["ghpython"]["outputParameters"]]
    tree = ast.parse((folder / "code.py").read_text(encoding="utf-8"))
    classes = [n for n in tree.body if isinstance(n, ast.ClassDef)]
    assert [c.name for c in classes] == [folder.name], "one class, named as the folder"
    bases = [ast.unparse(b) for b in classes[0].bases]
    assert bases == ["Grasshopper.Kernel.GH_ScriptInstance"]
    run = next(
        f for f in classes[0].body if isinstance(f, ast.FunctionDef) and f.name == "RunScript"
    )
    assert [a.arg for a in run.args.args] == ["self", *inputs]
    returns = [n for n in ast.walk(run) if isinstance(n, ast.Return)]
    assert returns
    for ret in returns:
        n = len(ret.value.elts) if isinstance(ret.value, ast.Tuple) else 1
        assert n == len(outputs), f"returns {n} values for outputs {outputs}"
    assert _png_size(folder / "icon.png") == (24, 24)
    assert meta["instanceGuid"] not in {
        json.loads((c / "metadata.json").read_text())["instanceGuid"]
        for c in COMPONENTS
        if c != folder
    }


def test_components_cover_the_pipeline() -> None:
    names = {c.name for c in COMPONENTS}
    assert {"RM_BuildSpec", "RM_ComputeConstants", "RM_RunPulse", "RM_RunEnvelope"} <= names
    assert "RM_RunHistory" in names


# ---------------------------------------------------------------------- pyright


@pytest.mark.slow
def test_glue_type_checks_against_rhinocommon() -> None:
    """pyright with rhino-stubs-typed on rhino_plugin/rhino and the components."""
    pyright = shutil.which("pyright", path=str(Path(sys.executable).parent)) or shutil.which(
        "pyright"
    )
    if pyright is None:
        pytest.skip("pyright is not installed (pip install -e '.[dev]')")
    if shutil.which("node") is None:
        pytest.skip("pyright needs node on PATH; it would otherwise download one")
    stubs = [Path(p) / "Rhino" / "__init__.pyi" for p in sys.path]
    if not any(p.is_file() for p in stubs):
        pytest.skip("rhino-stubs-typed is not installed (pip install -e '.[dev]')")
    done = subprocess.run(
        [pyright, "--pythonpath", sys.executable, "--outputjson"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=600,
    )
    report = json.loads(done.stdout)
    errors = [
        f"{d['file']}:{d['range']['start']['line'] + 1}: {d['message']}"
        for d in report["generalDiagnostics"]
        if d["severity"] == "error"
    ]
    assert not errors, "\n".join(errors)
    assert report["summary"]["filesAnalyzed"] >= len(SCRIPTS) + len(COMPONENTS)


# ---------------------------------------------------------------------- Python 3.9


def _py_files() -> List[Path]:
    files: List[Path] = []
    for p in RHINO_IMPORTED:
        files.extend(sorted(p.rglob("*.py")) if p.is_dir() else [p])
    return files


@pytest.mark.parametrize("path", _py_files(), ids=lambda p: str(p.relative_to(ROOT)))
def test_rhino_imported_module_parses_as_python_39(path: Path) -> None:
    ast.parse(path.read_text(encoding="utf-8"), filename=str(path), feature_version=(3, 9))


def test_rhino_imported_modules_pass_ruffs_39_rules() -> None:
    """No PEP 604 unions or other 3.10+ constructs that 3.9 would evaluate at runtime."""
    ruff = shutil.which("ruff", path=str(Path(sys.executable).parent)) or shutil.which("ruff")
    if ruff is None:
        pytest.skip("ruff is not installed")
    done = subprocess.run(
        [ruff, "check", "--isolated", "--target-version", "py39",
         "--select", "FA102,F821,E9,UP036", *map(str, RHINO_IMPORTED)],
        cwd=ROOT, capture_output=True, text=True,
    )  # fmt: skip
    assert done.returncode == 0, done.stdout + done.stderr


def _python39() -> Optional[str]:
    """A Python 3.9 interpreter: $ROCKMECH_PY39, then python3.9 on PATH, then ``py -3.9``."""
    candidates: List[List[str]] = []
    if os.environ.get("ROCKMECH_PY39"):
        candidates.append([os.environ["ROCKMECH_PY39"]])
    if shutil.which("python3.9"):
        candidates.append([str(shutil.which("python3.9"))])
    if shutil.which("py"):
        candidates.append([str(shutil.which("py")), "-3.9"])
    for cmd in candidates:
        try:
            done = subprocess.run(
                [*cmd, "-c", "import sys; print(sys.version_info[:2] == (3, 9))"],
                capture_output=True, text=True, timeout=60,
            )  # fmt: skip
        except OSError:
            continue
        if done.returncode == 0 and done.stdout.strip() == "True":
            return " ".join(cmd)
    return None


PY39_PROGRAM = r"""
import json, sys
from cad_maths.scene_3dm import Scene
from cad_maths.mechanisms.build import constants_from_spec
import rhino_plugin.flows.mechanisms, rhino_plugin.flows.analyse, rhino_plugin.flows.params
import rhino_plugin.flows.prepared, rhino_plugin.flows.marks
import shared_schema.api
from shared_schema.spec import parse_spec
scene_path, spec_path = sys.argv[1:3]
cf = constants_from_spec(parse_spec(open(spec_path, "rb").read()), Scene.from_3dm(scene_path),
                         scene_name="s", spec_name="s")
print(cf.model_dump_json(exclude_none=True))
"""


def test_constants_under_a_real_python_39(cli_constants: Any) -> None:
    """Import what Rhino imports and compute constants under CPython 3.9, equal to 3.11's."""
    py = _python39()
    if py is None:
        pytest.skip(
            "no Python 3.9 found (set ROCKMECH_PY39 to a python3.9 with numpy, pydantic, scipy, "
            "trimesh<=4.12, manifold3d, shapely and rhino3dm); ast and ruff 3.9 checks ran"
        )
    cmd = py.split(" ")
    deps = subprocess.run(
        [*cmd, "-c", "import numpy, pydantic, scipy, trimesh, rhino3dm, manifold3d, shapely"],
        capture_output=True, text=True,
    )  # fmt: skip
    if deps.returncode != 0:
        pytest.skip(f"{py} lacks the dependencies: {deps.stderr.strip().splitlines()[-1]}")
    program = PY39_PROGRAM
    if not (ROOT / "shared_schema" / "api.py").is_file():
        program = program.replace("import shared_schema.api\n", "")
    for stem in ("statue_column", "facade"):
        done = subprocess.run(
            [*cmd, "-c", program, str(ROOT / "examples/scenes" / f"{stem}.3dm"),
             str(ROOT / "examples/specs" / f"{stem}.spec.json")],
            cwd=ROOT, capture_output=True, text=True, env={**os.environ, "PYTHONPATH": str(ROOT)},
        )  # fmt: skip
        assert done.returncode == 0, done.stderr
        for mech in json.loads(done.stdout)["mechanisms"]:
            want = cli_constants(stem)[mech["id"]]
            for key in ("positive", "negative", "eta"):
                got, ref = mech.get(key), want.get(key)
                if ref is None:
                    assert got is None, key
                elif isinstance(ref, dict):
                    assert got.keys() == ref.keys()
                    for k in ref:
                        assert got[k] == pytest.approx(ref[k], rel=1e-12, abs=1e-14), (key, k)
                else:
                    assert got == pytest.approx(ref, rel=1e-12), key


# ---------------------------------------------------------------------- packaging


def _project_version() -> str:
    # The one source of the version (pyproject.toml reads it from there too).
    for line in (ROOT / "shared_schema" / "version.py").read_text().splitlines():
        if line.startswith("__version__ = "):
            return line.split('"')[1]
    raise AssertionError("no __version__ in shared_schema/version.py")


def test_rhproj_lists_every_command_and_the_libraries() -> None:
    proj = json.loads((ROOT / "rhino_plugin" / "rockmech.rhproj").read_text())
    assert proj["identity"]["name"] == "rockmech"
    assert proj["identity"]["version"] == _project_version()
    assert proj["settings"]["buildTarget"]["slug"] == "rh8"
    codes = {c["title"]: c for c in proj["codes"]}
    assert sorted(codes) == COMMANDS
    for code in codes.values():
        assert (ROOT / "rhino_plugin" / code["uri"]).is_file(), code["uri"]
        assert code["language"] == {"id": "*.*.python", "version": "3.*.*"}
    ids = [c["id"] for c in proj["codes"]] + [proj["id"]]
    assert len(set(ids)) == len(ids)
    bases = [
        (ROOT / "rhino_plugin" / lib["library"]["base"]).resolve() for lib in proj["libraries"]
    ]
    # The flows run the solver's workflows in Rhino: solver_service ships too.
    assert bases == [
        ROOT / "rhino_plugin",
        ROOT / "shared_schema",
        ROOT / "cad_maths",
        ROOT / "solver_service",
    ]


def test_yak_manifest_has_the_required_fields() -> None:
    text = (ROOT / "rhino_plugin" / "manifest.yml").read_text()
    fields = {
        line.split(":", 1)[0]: line.split(":", 1)[1].strip()
        for line in text.splitlines()
        if line and not line.startswith((" ", "#"))
    }
    assert {"name", "version", "authors", "description"} <= set(fields)
    assert fields["name"] == "rockmech"
    assert fields["version"] == _project_version()
    assert "  - " in text.split("authors:", 1)[1].split("\n", 2)[1]
