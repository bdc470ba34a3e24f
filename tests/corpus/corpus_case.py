"""The shared case runner of the bad-input corpus (issue #14).

A :class:`Case` is one ``rockmech`` command line and the answer it must get:

- ``error``: exit status 2 and a last stderr line ``error: <field>: <what is wrong>`` where the
  field and the problem match the case's patterns;
- ``ok``: exit status 0 (and, where given, a check of the JSON answer on stdout);
- ``warn``: exit status 0 and a warning on stderr matching the pattern;
- ``partial``: exit status 1 (``--keep-going``: some mechanisms failed, named on stderr).

Any traceback or any other exit status fails; a case that may hang runs in a child process
killed after ``HANG_SECONDS`` (a hang check, not a speed limit).
"""

from __future__ import annotations

import dataclasses
import json
import re
import subprocess
import sys
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Optional

import pytest
from typer.testing import CliRunner

from solver_service.cli import app

#: A case that may hang is taken to hang after this long [s] (far above any real answer).
HANG_SECONDS = 300.0

runner = CliRunner()


@dataclass
class Case:
    """One input and the answer it must get."""

    id: str
    argv: list[str]
    expect: str  # "error", "ok", "warn" or "partial"
    field: str = ""  # regex on the field named in the error line
    problem: str = ""  # regex on stderr (error, warn, partial)
    check: Optional[Callable[[Any], bool]] = None
    xfail: str = ""
    #: Run in a child process killed after ``HANG_SECONDS`` (cases that may hang).
    isolate: bool = False
    #: Files the case writes into its folder before running: name -> text or bytes.
    files: dict[str, Any] = dataclasses.field(default_factory=dict)


def params(cases: list[Case]) -> list[Any]:
    """The cases as pytest params, strict-xfail where the case names a #14 class."""
    return [
        pytest.param(c, id=c.id, marks=[pytest.mark.xfail(strict=True, reason=c.xfail)])
        if c.xfail
        else pytest.param(c, id=c.id)
        for c in cases
    ]


def _run_isolated(argv: list[str]) -> tuple[int, str, str]:
    """Run ``rockmech`` in a child process, killed after ``HANG_SECONDS``."""
    code = "import sys; from solver_service.cli import app; app(sys.argv[1:])"
    try:
        proc = subprocess.run(
            [sys.executable, "-c", code, *argv],
            capture_output=True,
            text=True,
            timeout=HANG_SECONDS,
            check=False,
        )
    except subprocess.TimeoutExpired:
        pytest.fail(f"no answer within {HANG_SECONDS:g} s (a hang)")
    assert "Traceback" not in proc.stderr, proc.stderr
    return proc.returncode, proc.stdout, proc.stderr


def run_case(case: Case, argv: list[str]) -> tuple[str, str]:
    """Run ``rockmech ARGV`` and assert the case's answer; return (stdout, stderr)."""
    if case.isolate:
        exit_code, stdout, stderr = _run_isolated(argv)
    else:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            res = runner.invoke(app, argv)
        # a numpy RuntimeWarning reaches the user as "path:line: RuntimeWarning: ..." on stderr
        leaked = [
            f"{w.filename}:{w.lineno}: {w.message}" for w in caught if w.category is RuntimeWarning
        ]
        assert not leaked, f"a RuntimeWarning reaches the user: {leaked}"
        if res.exception is not None and not isinstance(res.exception, SystemExit):
            raise AssertionError(f"traceback: {res.exception!r}\n{res.output}") from res.exception
        exit_code, stdout, stderr = res.exit_code, res.stdout, res.stderr
    assert "Traceback" not in stderr, stderr
    if case.expect == "error":
        assert exit_code == 2, f"exit {exit_code}\n{stdout}\n{stderr}"
        lines = [ln for ln in stderr.strip().splitlines() if ln.startswith("error: ")]
        assert lines, stderr
        assert re.search(case.problem or ".", stderr, re.I), stderr
        if case.field:
            # the field is on the error line, or on an indented line of a list of failures
            tail = stderr[stderr.index("error: ") :]
            assert re.search(rf"(error: |\n  )[^\n]*({case.field})", tail, re.I), stderr
        return stdout, stderr
    if case.expect == "partial":
        assert exit_code == 1, f"exit {exit_code}\n{stdout}\n{stderr}"
        assert re.search(case.problem or ".", stderr, re.I), stderr
    else:
        assert exit_code == 0, f"exit {exit_code}\n{stdout}\n{stderr}"
    if case.expect == "warn":
        assert re.search(r"warning", stderr, re.I) and re.search(case.problem, stderr, re.I), stderr
    if case.check is not None:
        doc: Any = stdout
        try:
            doc = json.loads(stdout)
        except ValueError:
            pass
        assert case.check(doc), stdout
    return stdout, stderr
