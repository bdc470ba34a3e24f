"""Every ``rockmech`` command line of README.md runs as written (issue #14: the README is data).

The commands are read from the README's fenced shell blocks. Each runs in a fresh folder that
holds the bundled ``examples/`` (outputs go there too): first as written with its optional
``[...]`` parts left out, then once with each optional part (each alternative of ``a|b``).
Each must exit 0 without a traceback and write what its ``-o``/``--out`` names (its parent
folders too). Placeholders are filled (``DIR``, ``N``); parts that need what a test machine
lacks (a Dask scheduler, headless Chromium) and commands that do not end (``serve``) or
rewrite the shipped library (``library build``) are skipped with the reason. A command whose
input file the repository does not ship fails: every file the README names is bundled.
"""

from __future__ import annotations

import json
import os
import re
import shlex
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from solver_service.cli import app

REPO = Path(__file__).resolve().parents[1]
README = REPO / "README.md"
#: Fenced blocks whose lines are shell commands.
SHELL_BLOCKS = ("bash", "sh", "shell", "console", "")
#: Placeholders of the README's synopses and what a run puts there.
PLACEHOLDERS = {"DIR": "out/readme", "N": "2"}
#: Options that may not run here, with the reason.
NOT_RUN_OPTIONS = {
    "--scheduler": "needs a running Dask scheduler",
    "--pdf": "prints with headless Chromium (tests/service/test_assess_report.py covers it)",
}
#: Commands that are not run, with the reason.
NOT_RUN_COMMANDS = {
    "serve": "serves until stopped (the service tests start it on a free port)",
    "examples": "copies into ./examples, which this test links to the repository's own "
    "(tests/test_cli.py runs it into a fresh folder; .ci/install_check from a wheel)",
    "kernels": "compiles every solver path, which the test session does before it starts "
    "(tests/conftest.py; tests/solver_core/test_jit.py runs the command)",
    "library build": "writes a library into the user's cache folder and takes about 4 s "
    "(tests/test_cli.py builds a small one there, in a temporary cache folder)",
}
#: Options whose value is a file the command writes (not an input that must exist).
OUTPUT_OPTIONS = {"-o", "--out"}
#: Variants the code answers otherwise than the README says: id -> reason (strict xfail).
README_DISAGREES: dict[str, str] = {}

runner = CliRunner()


@dataclass(frozen=True)
class Run:
    """One command line to run and why it might not."""

    id: str
    argv: tuple[str, ...]
    skip: str = ""


def _blocks(text: str) -> list[tuple[int, str]]:
    """``(line number, line)`` of every line inside a fenced shell block."""
    out, lang = [], None
    for number, line in enumerate(text.splitlines(), start=1):
        fence = re.match(r"^\s*```\s*(\w*)", line)
        if fence:
            lang = None if lang is not None else fence.group(1).lower()
            continue
        if lang is not None and lang in SHELL_BLOCKS:
            out.append((number, line))
    return out


def _groups(tokens: list[str]) -> tuple[list[str], list[list[str]]]:
    """Split a synopsis into the required tokens and its optional ``[...]`` groups."""
    base: list[str] = []
    groups: list[list[str]] = []
    current: list[str] | None = None
    for tok in tokens:
        if current is None and tok.startswith("["):
            current = []
            tok = tok[1:]
        if current is None:
            base.append(tok)
            continue
        closed = tok.endswith("]")
        current.append(tok[:-1] if closed else tok)
        if closed:
            groups.append([t for t in current if t])
            current = None
    return base, groups


def _alternatives(group: list[str]) -> list[list[str]]:
    """Each alternative of a group: ``--sf eq28|ec8`` -> ``--sf eq28``, ``--sf ec8``."""
    variants: list[list[str]] = [[]]
    for tok in group:
        options = tok.split("|") if "|" in tok and not tok.startswith("-") else [tok]
        variants = [[*v, PLACEHOLDERS.get(o, o)] for v in variants for o in options]
    return variants


def _missing_input(argv: list[str], folder: Path) -> str:
    """The first input file of ``argv`` that is not in ``folder`` (relative paths), or ''."""
    for i, tok in enumerate(argv):
        if tok.startswith("-") or (i and argv[i - 1] in OUTPUT_OPTIONS):
            continue
        if re.search(r"\.[A-Za-z][\w]*$", tok) and not (folder / tok).exists():
            return tok
    return ""


def _runs() -> list[Run]:
    runs: list[Run] = []
    for number, line in _blocks(README.read_text(encoding="utf-8")):
        if not line.strip().startswith("rockmech "):
            continue
        tokens = shlex.split(line, comments=True)[1:]
        base, groups = _groups(tokens)
        name = base[0]
        skip = NOT_RUN_COMMANDS.get(" ".join(base[:2]), NOT_RUN_COMMANDS.get(name, ""))
        runs.append(Run(f"L{number}:{name}", tuple(base), skip))
        for group in groups:
            for alt in _alternatives(group):
                why = skip or next((w for o, w in NOT_RUN_OPTIONS.items() if o in alt), "")
                runs.append(Run(f"L{number}:{name}[{' '.join(alt)}]", (*base, *alt), why))
    return runs


RUNS = _runs()


def _key(run: Run) -> str:
    """The id without the line number: what ``README_DISAGREES`` names."""
    return run.id.split(":", 1)[1]


@pytest.mark.parametrize(
    "run",
    [
        pytest.param(r, id=r.id, marks=[pytest.mark.xfail(strict=True, reason=README_DISAGREES[k])])
        if (k := _key(r)) in README_DISAGREES
        else pytest.param(r, id=r.id)
        for r in RUNS
    ],
)
def test_readme_command_runs(run: Run, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    if run.skip:
        pytest.skip(run.skip)
    os.symlink(REPO / "examples", tmp_path / "examples")
    missing = _missing_input(list(run.argv), tmp_path)
    assert not missing, f"README uses {missing}, which the repository does not ship"
    monkeypatch.chdir(tmp_path)
    res = runner.invoke(app, list(run.argv))
    if res.exception is not None and not isinstance(res.exception, SystemExit):
        raise AssertionError(f"traceback: {res.exception!r}\n{res.output}") from res.exception
    assert "Traceback" not in res.output, res.output
    assert res.exit_code == 0, f"exit {res.exit_code}\n{res.stdout}\n{res.stderr}"
    for option, value in zip(run.argv, run.argv[1:]):
        if option in OUTPUT_OPTIONS:
            assert (tmp_path / value).exists(), f"{option} {value} was not written"


def test_the_readme_has_commands_of_every_kind() -> None:
    """The extraction finds the README's commands (a change of its layout must not hide them)."""
    names = {r.argv[0] for r in RUNS}
    assert {"pulse", "history", "record", "envelope", "boundary", "demo", "assess"} <= names
    assert len(RUNS) >= 30


def _python_blocks(text: str) -> list[str]:
    """The source of every fenced ``python`` block."""
    return re.findall(r"^```python\n(.*?)^```", text, flags=re.S | re.M)


def test_the_readme_python_runs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The README's Python example runs as written, and its pulse answers as the CLI's does."""
    blocks = _python_blocks(README.read_text(encoding="utf-8"))
    assert blocks, "README.md has no python block"
    monkeypatch.chdir(tmp_path)
    scope: dict[str, Any] = {}
    for source in blocks:
        exec(compile(source, str(README), "exec"), scope)  # the README's own code
    assert (tmp_path / "facade.json").is_file()
    res = scope["res"]
    cli = runner.invoke(
        app, "pulse --p-eq 2.2 --lam 0.165 --eta 0.96 --a-p-g -0.3 --f-p 1.0 --json".split()
    )
    assert cli.exit_code == 0, cli.output
    doc = json.loads(cli.stdout)
    assert (res.overturned, res.t_overturn) == (doc["overturned"], doc["t_overturn"])
