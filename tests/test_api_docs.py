"""docs/api.md runs as written, from ``import rockmech`` alone (#28, #38).

Every function of ``rockmech.__all__`` is shown there in an example and named in its table,
the page runs as a doctest in a fresh process in an empty folder (in the quick suite), and
the facade's analyses give the command line's numbers (the same workflow, checked against
``rockmech ... --json``).
"""

from __future__ import annotations

import inspect
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

import rockmech
from shared_schema.errors import InputError
from solver_service.cli import app

ROOT = Path(__file__).resolve().parents[1]
API_MD = ROOT / "docs" / "api.md"
EXAMPLES = ROOT / "examples"
runner = CliRunner()


def _code_lines() -> list[str]:
    return [
        line[4:]
        for line in API_MD.read_text(encoding="utf-8").splitlines()
        if line.startswith((">>> ", "... "))
    ]


def _functions() -> list[str]:
    return [
        name
        for name in rockmech.__all__
        if name != "__version__"
        and callable(getattr(rockmech, name))
        and not inspect.isclass(getattr(rockmech, name))
    ]


def test_every_public_function_is_shown_in_an_example() -> None:
    code = "\n".join(_code_lines())
    functions = _functions()
    assert len(functions) >= 25
    missing = [name for name in functions if f"rockmech.{name}(" not in code]
    assert not missing, f"docs/api.md shows no call of {missing}"


def test_every_public_function_is_in_the_table() -> None:
    page = API_MD.read_text(encoding="utf-8")
    table = "\n".join(line for line in page.splitlines() if line.startswith("| `"))
    missing = [name for name in _functions() if f"`{name}(" not in table]
    assert not missing, f"docs/api.md's table does not name {missing}"


def test_the_names_follow_one_verb_scheme() -> None:
    """read_* reads, write_* writes (the object first), no load_/save_ alias (#38)."""
    names = _functions()
    assert not [n for n in names if n.startswith(("load_", "save_", "get_"))], names
    for name in (n for n in names if n.startswith("write_")):
        first = next(iter(inspect.signature(getattr(rockmech, name)).parameters))
        assert first not in {"path", "out", "dest"}, f"{name}: the object comes first"
    assert "measure" in inspect.signature(rockmech.ida).parameters
    assert "im" not in inspect.signature(rockmech.ida).parameters


def test_the_examples_use_the_facade_alone() -> None:
    lines = _code_lines()
    imports = [line for line in lines if re.match(r"\s*(import|from)\s", line)]
    assert imports == ["import rockmech"], imports
    packages = r"shared_schema|cad_maths|solver_service|rhino_plugin"
    inner = [line for line in lines if re.search(packages, line)]
    assert not inner, inner


def test_docs_api_runs_as_a_doctest_in_an_empty_folder(tmp_path: Path) -> None:
    """In the quick suite: the page runs in about 9 s (one search, one report's figures)."""
    code = (
        "import doctest, sys\n"
        f"r = doctest.testfile({str(API_MD)!r}, module_relative=False, "
        "optionflags=doctest.ELLIPSIS)\n"
        "print(r.attempted, r.failed)\n"
        "sys.exit(1 if r.failed else 0)\n"
    )
    res = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, timeout=300
    )
    assert res.returncode == 0, res.stdout[-4000:]
    attempted, failed = map(int, res.stdout.split()[-2:])
    assert attempted >= 60 and failed == 0
    # The examples wrote only into the empty folder.
    assert (tmp_path / "facade.json").is_file() and (tmp_path / "walls.html").is_file()
    assert (tmp_path / "examples" / "records" / "elcentro_NS.dat").is_file()


def _cli_json(args: list[str]) -> dict:
    res = runner.invoke(app, [*args, "--json"])
    assert res.exit_code == 0, res.output
    return json.loads(res.stdout)


def _without_times(doc: object) -> object:
    if isinstance(doc, dict):
        return {k: _without_times(v) for k, v in doc.items() if "runtime" not in k}
    if isinstance(doc, list):
        return [_without_times(v) for v in doc]
    return doc


def test_facade_analyses_give_the_command_lines_numbers(tmp_path: Path) -> None:
    walls = EXAMPLES / "constants" / "rect_walls.json"
    record = EXAMPLES / "records" / "elcentro_NS.dat"
    cli = _cli_json(["history", str(walls), str(record), "--scale", "0.5", "1"])
    facade = rockmech.history(walls, record, scales=[0.5, 1.0])
    assert _without_times(facade.to_dict()) == _without_times(cli)
    assert [(r.mechanism, r.scale, r.peak_ratio) for r in facade.results] == [
        (r["mechanism"], r["scale"], r["peak_ratio"]) for r in cli["results"]
    ]
    church = EXAMPLES / "constants" / "church_geometry.json"
    site = EXAMPLES / "sites" / "ntc_site.json"
    cli = _cli_json(["check", str(church), str(site)])
    checks = rockmech.check(church, site)
    assert checks.to_dict() == cli and checks.governing == cli["governing"]
    for row, typed in zip(cli["mechanisms"], checks.mechanisms):
        assert typed.linear_ratio == row["linear"]["capacity_ratio"]
        assert typed.passes is row["passes"]
        assert typed.passes_SLC is row["nonlinear"]["SLC"]["passes"] is row["passes_SLC"]
    cli = _cli_json(
        [
            "envelope",
            str(EXAMPLES / "constants" / "church.json"),
            "--n",
            "7",
            "--out",
            str(tmp_path / "env"),
        ]
    )
    env = rockmech.envelope(EXAMPLES / "constants" / "church.json", n=7)
    assert _without_times(env.to_dict()) == _without_times(cli)
    assert env.f_p == cli["f_p"]
    assert env.find("F1").a_p_min_g == cli["mechanisms"][0]["a_p_min_g"]


def test_a_run_or_mechanism_not_in_a_result_is_named_with_those_that_are() -> None:
    walls = EXAMPLES / "constants" / "rect_walls.json"
    record = EXAMPLES / "records" / "elcentro_NS.dat"
    result = rockmech.history(walls, record, scales=[1.0])
    with pytest.raises(InputError, match=r"no run 'W9 x1'; the document has \['F1 x1', 'W1 x1'"):
        result.find("W9", 1.0)
    checks = rockmech.check(
        EXAMPLES / "constants" / "church_geometry.json", EXAMPLES / "sites" / "ntc_site.json"
    )
    with pytest.raises(InputError, match=r"no mechanism 'X'; the document has \['F1', 'F2'"):
        checks.find("X")
