"""rockmech installs like a library (#15): public package, version, extras, wheel and sdist.

The end-to-end check (the wheel in a fresh virtual environment) is ``make install-check``
(``.ci/install_check``), run by ``.ci/run``; these tests check the pieces in process.
"""

from __future__ import annotations

import email
import json
import math
import os
import shutil
import subprocess
import sys
import tarfile
import zipfile
from pathlib import Path

import pytest
import tomllib
from typer.testing import CliRunner

import rockmech
from shared_schema.errors import RockmechError
from shared_schema.extras import EXTRAS, MissingExtra, extra_for, require
from solver_service.api.jobs import run_job
from solver_service.api.jobspec import SceneJob
from solver_service.cli import app
from solver_service.core.exact import simulate
from solver_service.core.excitation import Pulse
from solver_service.core.model import RockingModel
from solver_service.demo import examples_dir

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())
runner = CliRunner()

#: The public API of ``import rockmech`` (changing it is an API change: update the docs).
PUBLIC = [
    "__version__",
    "RockmechError",
    "InputError",
    "GeometryError",
    "SolverError",
    "MissingExtra",
    "ConstantsFile",
    "read_constants",
    "write_constants",
    "constants_from_scene",
    "models_from_constants",
    "read_record",
    "read_site",
    "SiteFile",
    "pulse",
    "history",
    "envelope",
    "ida",
    "check",
    "assess",
    "retrofit",
    "RetrofitSpec",
    "RetrofitDoc",
    "read_retrofit_spec",
    "RockingResult",
    "BatchResult",
    "HistoryDocument",
    "HistoryRow",
    "RecordDocument",
    "EnvelopeDocument",
    "Band",
    "IdaDocument",
    "IdaMechanism",
    "CheckDocument",
    "CheckMechanism",
    "AssessDocument",
    "G",
    "RockingModel",
    "Pulse",
    "SampledAccel",
    "GroundMotion",
    "simulate",
    "simulate_batch",
    "PulseRequest",
    "PulseDocument",
    "BoundaryDocument",
    "solve_pulse",
    "mechanism_envelope",
    "critical_bands",
    "extract_pulses",
    "largest_pulse",
    "response_spectrum",
    "search",
    "SearchRun",
    "SearchDocument",
    "SearchCandidate",
    "write_search",
    "read_search_spec",
    "read_scene",
    "build_report",
    "write_report",
    "examples_dir",
    "copy_examples",
    "kernel_status",
    "KernelStatus",
]


# ------------------------------------------------------------------ the public package


def test_public_api_is_pinned_and_every_name_is_the_source_object() -> None:
    assert rockmech.__all__ == PUBLIC
    assert set(PUBLIC) <= set(dir(rockmech))
    for name in PUBLIC[1:]:
        value = getattr(rockmech, name)
        source = __import__(rockmech._SOURCES[name], fromlist=[name])
        assert value is getattr(source, name), name
    with pytest.raises(AttributeError, match="no attribute 'simulat'"):
        rockmech.simulat  # noqa: B018


def test_import_rockmech_loads_no_heavy_module() -> None:
    code = (
        "import sys, rockmech; "
        "print(sorted({m.split('.')[0] for m in sys.modules} & "
        "{'numpy', 'scipy', 'matplotlib', 'numba', 'rhino3dm', 'pydantic', 'typer'}))"
    )
    res = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=60
    )
    assert res.returncode == 0, res.stderr
    assert res.stdout.strip() == "[]"


def test_readme_example_through_rockmech_gives_the_solver_numbers() -> None:
    wall = rockmech.RockingModel.symmetric(p_eq=2.2, lam=0.165, eta=0.96, name="W2")
    res = rockmech.simulate(wall, rockmech.Pulse(a_p=-3.0, f_p=1.0))
    direct = simulate(RockingModel.symmetric(2.2, 0.165, 0.96), Pulse(a_p=-3.0, f_p=1.0))
    assert res.peak_ratio == direct.peak_ratio and res.overturned == direct.overturned
    record = rockmech.examples_dir() / "records" / "elcentro_NS.dat"
    motion = rockmech.GroundMotion.from_two_column(record, units="g")
    # El Centro 1940 N-S: 2688 points at 0.02 s, PGA 0.349 g (the bundled record's README).
    assert len(motion.accel.acc) == 2688 and motion.dt == 0.02
    assert math.isclose(motion.pga_g, 0.349, abs_tol=5e-4)
    batch = rockmech.simulate_batch([wall], motion.accel, scales=[1.0])
    assert batch.peak_ratio.shape == (1, 1)


def test_version_is_written_once_and_the_rhino_copies_agree() -> None:
    project = PYPROJECT["project"]
    assert "version" not in project and project["dynamic"] == ["version"]
    attr = PYPROJECT["tool"]["setuptools"]["dynamic"]["version"]["attr"]
    assert attr == "shared_schema.version.__version__"
    version = rockmech.__version__
    assert version.count(".") == 2 and all(p.isdigit() for p in version.split("."))
    rhproj = json.loads((ROOT / "rhino_plugin" / "rockmech.rhproj").read_text())
    assert rhproj["identity"]["version"] == version
    manifest = (ROOT / "rhino_plugin" / "manifest.yml").read_text()
    assert f"\nversion: {version}\n" in manifest
    assert f"\nversion: {version}\n" in (ROOT / "CITATION.cff").read_text()
    res = runner.invoke(app, ["--version"])
    assert res.exit_code == 0 and res.stdout.splitlines()[0] == f"rockmech {version}"


def test_licence_metadata_is_pep639() -> None:
    project = PYPROJECT["project"]
    assert project["license"] == "MIT" and project["license-files"] == ["LICENSE"]
    assert (ROOT / "LICENSE").read_text().startswith("MIT License")
    assert not any(c.startswith("License ::") for c in project["classifiers"])
    assert project["urls"]


def test_citation_names_the_methods_paper() -> None:
    text = (ROOT / "CITATION.cff").read_text()
    assert text.startswith("cff-version: 1.2.0\n")
    preferred = text.split("preferred-citation:", 1)[1].split("\nreferences:", 1)[0]
    for needed in (
        "family-names: Mehrotra",
        "family-names: DeJong",
        "year: 2018",
        "journal: Engineering Structures",
        "type: article",
    ):
        assert needed in preferred, needed


def test_all_extra_is_every_user_extra_and_dev_builds_on_it() -> None:
    extras = PYPROJECT["project"]["optional-dependencies"]
    (all_line,) = extras["all"]
    users = set(extras) - {"all", "dev"}
    assert all_line == f"rockmech[{','.join(sorted(users, key=all_line.index))}]"
    assert set(all_line[len("rockmech[") : -1].split(",")) == users
    assert "rockmech[all]" in extras["dev"]


def test_python_dash_m_rockmech_is_the_command() -> None:
    res = subprocess.run(
        [sys.executable, "-m", "rockmech", "--version"],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=120,
    )
    assert res.returncode == 0, res.stderr
    assert res.stdout.splitlines()[0] == f"rockmech {rockmech.__version__}"
    res = subprocess.run(
        [sys.executable, "-m", "rockmech", "pulse", "--p-eq", "2"],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=120,
    )
    assert res.returncode == 2 and res.stderr.startswith("error: --a-p-g: missing option")


def test_the_cli_dependencies_are_in_the_base_install() -> None:
    base = {_dist(r) for r in PYPROJECT["project"]["dependencies"]}
    assert {"numpy", "pydantic", "scipy", "matplotlib", "typer", "rich", "numba"} <= base
    for extra in ("geometry", "service", "dask", "report", "tables"):
        assert not base & {_dist(r) for r in PYPROJECT["project"]["optional-dependencies"][extra]}


def _dist(requirement: str) -> str:
    for stop in "<>=!~;[ ":
        requirement = requirement.split(stop, 1)[0]
    return requirement.lower()


def test_every_package_of_the_tree_is_in_the_wheel_list() -> None:
    listed = set(PYPROJECT["tool"]["setuptools"]["packages"])
    mapped = PYPROJECT["tool"]["setuptools"]["package-dir"]
    assert mapped == {"solver_service.data.examples": "examples"}
    # Every folder holding Python modules (solver_service.core is a namespace package), except
    # the Grasshopper components, which are package data of rhino_plugin.
    found = {
        ".".join(module.parent.relative_to(ROOT).parts)
        for top in ("rockmech", "shared_schema", "cad_maths", "solver_service", "rhino_plugin")
        for module in (ROOT / top).rglob("*.py")
        if "components" not in module.relative_to(ROOT).parts
    }
    assert listed - set(mapped) == found


def test_bundled_examples_are_package_data() -> None:
    globs = PYPROJECT["tool"]["setuptools"]["package-data"]["solver_service.data.examples"]
    shipped = {p for g in globs for p in (ROOT / "examples").glob(g)}
    for needed in (
        "records/elcentro_NS.dat",
        "records/README.md",
        "constants/church.json",
        "constants/rect_walls.json",
        "constants/walls.csv",
        "scenes/facade.3dm",
        "specs/facade.spec.json",
        "scenes/scan_wall.ply",
        "specs/scan_wall_ply.spec.json",
    ):
        assert ROOT / "examples" / needed in shipped, needed
    # Every scene has its spec, both shipped (a scan's spec is named <stem>_<format>).
    scenes = {p.stem for p in shipped if p.suffix == ".3dm"}
    scenes |= {f"{p.stem}_{p.suffix[1:]}" for p in shipped if p.suffix == ".ply"}
    specs = {p.name.removesuffix(".spec.json") for p in shipped if p.name.endswith(".spec.json")}
    assert scenes == specs and len(scenes) >= 8
    assert examples_dir() == ROOT / "examples"


# ------------------------------------------------------------------ missing extras


def test_require_returns_the_module_or_names_the_extra_and_its_install_line() -> None:
    assert require("json", "none") is json
    with pytest.raises(MissingExtra) as info:
        require("rockmech_no_such_module", "geometry", "to read .3dm scenes")
    exc = info.value
    assert isinstance(exc, RockmechError) and isinstance(exc, ImportError)
    assert exc.name == "rockmech_no_such_module" and exc.extra == "geometry"
    assert exc.install == "pip install 'rockmech[geometry]'"
    assert str(exc) == (
        "rockmech_no_such_module is not installed (needed to read .3dm scenes); install the "
        "'geometry' extra: pip install 'rockmech[geometry]'"
    )


def test_require_names_the_missing_dependency_of_an_installed_module(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # dask.distributed present but its dependency gone: the message names the missing one.
    monkeypatch.setitem(sys.modules, "distributed", None)
    monkeypatch.delitem(sys.modules, "dask.distributed", raising=False)
    with pytest.raises(MissingExtra, match=r"^distributed is not installed; .*rockmech\[dask\]'$"):
        require("dask.distributed", "dask")


def test_extras_table_matches_pyproject() -> None:
    extras = PYPROJECT["project"]["optional-dependencies"]
    dist_of = {"multipart": "python-multipart", "ghhops_server": "ghhops-server"}
    dist_of |= {"pydantic_settings": "pydantic-settings", "dask": "distributed"}
    for module, extra in EXTRAS.items():
        assert dist_of.get(module, module) in {_dist(r) for r in extras[extra]}, module
    assert extra_for("dask.distributed") == "dask" and extra_for("numpy") is None


def _one_line_error(args: list[str]) -> str:
    res = runner.invoke(app, args)
    assert res.exit_code == 2, res.output
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), res.stderr
    return lines[0]


def test_cli_constants_without_the_geometry_extra_exits_2_with_the_install_line(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    ex = examples_dir()
    args = ["constants", str(ex / "scenes" / "facade.3dm"), str(ex / "specs" / "facade.spec.json")]
    args += ["-o", str(tmp_path / "c.json")]
    for module, purpose in (("rhino3dm", "to read .3dm scenes"), ("shapely", "")):
        with monkeypatch.context() as m:
            m.setitem(sys.modules, module, None)
            line = _one_line_error(args)
        assert line.startswith(f"error: {module} is not installed"), line
        assert purpose in line and line.endswith("pip install 'rockmech[geometry]'")
    assert not (tmp_path / "c.json").exists()


def test_cli_ida_scheduler_without_dask_exits_2_with_the_install_line(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setitem(sys.modules, "dask", None)
    monkeypatch.setitem(sys.modules, "dask.distributed", None)
    ex = examples_dir()
    line = _one_line_error(
        [
            "ida",
            str(ex / "constants" / "rect_walls.json"),
            str(ex / "records" / "elcentro_NS.dat"),
            "--scales",
            "1",
            "--scheduler",
            "tcp://127.0.0.1:1",
        ]
    )
    assert "(needed for ida --scheduler)" in line
    assert line.endswith("pip install 'rockmech[dask]'")


def test_cli_serve_without_the_service_extra_exits_2_with_the_install_line(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setitem(sys.modules, "uvicorn", None)
    line = _one_line_error(["serve", "--port", "1"])
    assert line == (
        "error: uvicorn is not installed (needed for rockmech serve); install the 'service' "
        "extra: pip install 'rockmech[service]'"
    )


def test_cli_names_the_extra_of_a_stray_missing_module(monkeypatch: pytest.MonkeyPatch) -> None:
    # The safety net of the CLI: a heavy import that bypasses require() still gets the line.
    from solver_service.workflows import documents

    def boom(*args: object, **kwargs: object) -> None:
        raise ModuleNotFoundError("No module named 'trimesh'", name="trimesh")

    monkeypatch.setattr(documents, "boundary_doc", boom)
    line = _one_line_error(["boundary", "--omega", "5", "--eta", "0.9"])
    assert line.endswith("pip install 'rockmech[geometry]'") and "trimesh" in line


@pytest.mark.slow  # the quick loop's budget: the whole suite (CI) runs it
def test_demo_without_the_geometry_extra_runs_and_says_what_it_skipped(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    monkeypatch.setitem(sys.modules, "rhino3dm", None)
    res = runner.invoke(app, ["demo", "--out", str(tmp_path)])
    assert res.exit_code == 0, res.output
    assert "note: skipped the CAD example" in res.stderr
    assert "pip install 'rockmech[geometry]'" in res.stderr
    assert (tmp_path / "history.json").is_file() and (tmp_path / "church_history.png").is_file()
    assert not (tmp_path / "facade_constants.json").exists()
    assert "note:" not in res.stdout


def test_service_answers_501_with_the_install_line_for_a_missing_geometry_module(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    ex = examples_dir()
    blobs = [
        (ex / "scenes" / "facade.3dm").read_bytes(),
        (ex / "specs" / "facade.spec.json").read_bytes(),
    ]
    job = SceneJob(scene_name="facade.3dm", spec_name="facade.spec.json")
    limits = {"max_samples": 500_000, "max_mechanisms": 100, "max_scales": 100}
    ok = run_job(job, blobs, limits)
    assert ok.status == 200
    # rhino3dm present, shapely absent (the slim image before #15 answered 500 here).
    monkeypatch.setitem(sys.modules, "shapely", None)
    out = run_job(job, blobs, limits)
    assert out.status == 501
    body = json.loads(out.body)
    assert "shapely is not installed" in json.dumps(body)
    assert "pip install 'rockmech[geometry]'" in json.dumps(body)


# ------------------------------------------------------------------ wheel and sdist


@pytest.fixture(scope="module")
def dists(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    try:
        import build  # noqa: F401
    except ImportError:
        pytest.skip("the build package is not installed (pip install build, part of [dev])")
    if not (ROOT / ".git").exists():
        pytest.skip("not a git checkout: the sdist is compared with `git ls-files`")
    out = tmp_path_factory.mktemp("dist")
    # Copy the tracked files only, so that a build/ or egg-info left in the tree cannot leak.
    src = tmp_path_factory.mktemp("src")
    for name in _tracked():
        (src / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / name, src / name)
    res = subprocess.run(
        [sys.executable, "-m", "build", "--outdir", str(out), str(src)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert res.returncode == 0, res.stdout[-3000:] + res.stderr[-3000:]
    (wheel,) = out.glob("*.whl")
    (sdist,) = out.glob("*.tar.gz")
    return {"wheel": wheel, "sdist": sdist}


def _tracked() -> list[str]:
    res = subprocess.run(
        ["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, text=True, check=True
    )
    return [n for n in res.stdout.split("\0") if n and (ROOT / n).is_file()]


@pytest.mark.slow
def test_wheel_holds_the_packages_examples_licence_and_metadata(dists: dict[str, Path]) -> None:
    version = rockmech.__version__
    with zipfile.ZipFile(dists["wheel"]) as whl:
        names = set(whl.namelist())
        meta = email.message_from_bytes(whl.read(f"rockmech-{version}.dist-info/METADATA"))
        scripts = whl.read(f"rockmech-{version}.dist-info/entry_points.txt").decode()
    assert meta["License-Expression"] == "MIT" and meta["Version"] == version
    assert f"rockmech-{version}.dist-info/licenses/LICENSE" in names
    assert "rockmech = solver_service.cli:main" in scripts
    base = {_dist(r) for r in meta.get_all("Requires-Dist") if "extra ==" not in r}
    assert {"typer", "rich", "scipy", "matplotlib", "numpy", "pydantic"} <= base
    examples = ROOT / "examples"
    for path in examples.rglob("*"):
        rel = path.relative_to(examples).as_posix()
        inside = f"solver_service/data/examples/{rel}"
        if path.suffix in (".3dm", ".ply", ".dat", ".csv") or path.name.endswith(".json"):
            assert inside in names, rel
    assert "solver_service/data/examples/scenes/build_scenes.py" not in names
    assert {"rockmech/__init__.py", "rockmech/_version.py", "shared_schema/extras.py"} <= names
    assert not any(n.startswith(("tests/", "benchmarks/", "docs/")) for n in names)


@pytest.mark.slow
def test_sdist_holds_every_tracked_file(dists: dict[str, Path]) -> None:
    with tarfile.open(dists["sdist"]) as tar:
        top = f"rockmech-{rockmech.__version__}/"
        names = {m.name.removeprefix(top) for m in tar.getmembers() if m.isfile()}
    missing = sorted(set(_tracked()) - names)
    assert not missing, missing


def test_version_warns_when_a_top_level_package_comes_from_elsewhere(tmp_path: Path) -> None:
    # Another distribution (or a folder on the path) named rhino_plugin, first on sys.path:
    # --version names it and where it comes from (docs/install.md, "Package names").
    other = tmp_path / "rhino_plugin"
    other.mkdir()
    (other / "__init__.py").write_text(
        "from pkgutil import extend_path\n__path__ = extend_path(__path__, __name__)\n"
    )
    res = subprocess.run(
        [sys.executable, "-m", "rockmech", "--version"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env={**os.environ, "PYTHONPATH": str(tmp_path)},
        timeout=120,
    )
    assert res.returncode == 0, res.stderr
    assert res.stderr == (
        f"warning: rhino_plugin is loaded from {tmp_path.resolve()}, not from rockmech's "
        f"install ({ROOT}): another package or file has that name (docs/install.md)\n"
    )
    # From another folder, without it on the path: no warning.
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    clean = subprocess.run(
        [sys.executable, "-m", "rockmech", "--version"],
        capture_output=True,
        text=True,
        cwd=elsewhere,
        timeout=120,
    )
    assert clean.returncode == 0 and clean.stderr == ""
