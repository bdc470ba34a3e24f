"""Every docstring example of the project's packages runs, as written.

The modules' NumPy docstrings carry ``Examples`` sections (``>>>`` lines). Each module with
one is a case here, run by the standard library's ``doctest`` with its default options
(what ``python -m doctest`` does), so a stale example fails and names its module. The
modules are found from the files, not a hand list nor ``pkgutil`` (which does not walk
``solver_service.core``, a namespace package), and each case checks that ``doctest`` sees
every ``>>>`` line of the file: an example where it cannot look (a string that is not a
docstring, a function whose wrapper hides it) fails instead of going unread.

The examples run from a fresh folder holding a link to the repository's ``examples/``, as
from the root of a clone (they name ``examples/...`` files) without writing into it.
"""

from __future__ import annotations

import doctest
import importlib
import io
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("shared_schema", "cad_maths", "solver_service", "rockmech", "rhino_plugin")
#: Module prefixes not imported here, and why; none may carry an example (checked below).
NOT_IMPORTABLE = {
    "rhino_plugin.rhino": "Rhino-only glue: imports RhinoCommon (Rhino.Geometry, Rhino.RhinoDoc,"
    " Rhino.DocObjects) at the top, which exist only inside Rhino 8 (the typed stubs that"
    " mypy reads make `import Rhino` succeed here, without the classes)",
    "rhino_plugin.components": "Grasshopper component scripts (code.py run by Grasshopper with"
    " its own globals), not modules of a package",
}
#: Examples that fail today, by docstring, and why: each must still fail (an example that
#: passes again is taken off), and no other example of its module may.
KNOWN_STALE: dict[str, str] = {}
PROMPT = re.compile(r"^\s*>>>", re.MULTILINE)


def _module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _sources() -> dict[str, Path]:
    files = (p for pkg in PACKAGES for p in sorted((ROOT / pkg).rglob("*.py")))
    return {_module_name(p): p for p in files if "__pycache__" not in p.parts}


def _skipped(name: str) -> bool:
    return any(name == pre or name.startswith(pre + ".") for pre in NOT_IMPORTABLE)


SOURCES = _sources()
WITH_EXAMPLES = sorted(
    name
    for name, path in SOURCES.items()
    if not _skipped(name) and PROMPT.search(path.read_text(encoding="utf-8"))
)


def test_the_modules_are_found_and_the_left_out_ones_carry_no_example() -> None:
    assert len(WITH_EXAMPLES) >= 60
    assert {"solver_service.core.exact", "cad_maths.scenes", "rockmech"} <= set(WITH_EXAMPLES)
    for prefix in NOT_IMPORTABLE:
        left_out = [name for name in SOURCES if _skipped(name) and name.startswith(prefix)]
        assert left_out, f"{prefix} names no module"
        with_examples = [n for n in left_out if PROMPT.search(SOURCES[n].read_text("utf-8"))]
        assert not with_examples, f"examples no test runs (move them): {with_examples}"
    stale_modules = {name.rsplit(".", 1)[0] for name in KNOWN_STALE}
    assert stale_modules <= set(WITH_EXAMPLES)


@pytest.mark.parametrize("name", WITH_EXAMPLES)
def test_docstring_examples_run(name: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    module = importlib.import_module(name)
    tests = [t for t in doctest.DocTestFinder().find(module, name) if t.examples]
    prompts = len(PROMPT.findall(SOURCES[name].read_text(encoding="utf-8")))
    found = sum(len(t.examples) for t in tests)
    assert found == prompts, (
        f"{name} has {prompts} '>>>' lines, doctest finds {found} examples: one sits where"
        " doctest does not look (not a docstring of the module's own objects)"
    )
    (tmp_path / "examples").symlink_to(ROOT / "examples", target_is_directory=True)
    monkeypatch.chdir(tmp_path)
    runner = doctest.DocTestRunner(optionflags=0)
    report = io.StringIO()
    failed = []
    for test in tests:
        if runner.run(test, out=report.write).failed:
            failed.append(test.name)
    assert [p.name for p in tmp_path.iterdir()] == ["examples"], "an example left files behind"
    known = {t.name for t in tests} & KNOWN_STALE.keys()
    unexpected = [n for n in failed if n not in known]
    assert not unexpected, report.getvalue()
    passing = sorted(known - set(failed))
    assert not passing, f"{passing} pass again: take them off KNOWN_STALE"
    if known:
        pytest.xfail("; ".join(f"{n}: {KNOWN_STALE[n]}" for n in sorted(known)))
