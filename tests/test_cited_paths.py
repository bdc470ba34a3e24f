"""Every file path the code, the docs and the tests cite exists inside the repository.

A citation is a path in the text of a module (its docstrings, comments and messages) or of a
Markdown page: ``docs/records.md``, ``solver_service/core/formats/__init__.py``,
``tests/golden/``. A path whose first part is a top-level entry of the repository
(``solver_service/...``, ``docs/...``, ``examples/...``) must exist from the root; a
``.py`` or ``.md`` path that does not start so (``core/records.py``, ``workflows/verdict.py``,
``theory.md``) must exist beside the citing file, above it, or under a package; a Markdown
file named on its own in capitals (``CONTRIBUTING.md``, ``STYLE.md``) must exist at the root,
in ``docs/`` or beside the citing file. Nothing may cite the project's shared folder beside
the repository as ``../shared/``: a clone does not have it.

CHANGELOG.md is not read: its entries name the paths of their time, moved or removed since.
Placeholders (``<name>``, ``*``, ``{x}``) are not paths.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: What a folder walk leaves out: tools' caches, environments and build outputs, and
#: ``out/``, where the README's commands write (``make demo``; git ignores all of these): a
#: citation of ``out/church`` names an output, not a file of the repository.
SKIP_DIRS = {
    ".git",
    ".venv",
    "venv",
    "build",
    "dist",
    "out",
    "__pycache__",
    ".mypy_cache",
    ".pytest_cache",
    ".ruff_cache",
    ".hypothesis",
    ".schemathesis",
    "node_modules",
}
#: Paths cited on purpose that are not in the tree, each with why (a prefix covers below it).
NOT_IN_THE_TREE = {
    "solver_service/data/examples": "package data: the build copies examples/ there (pyproject)",
    "rhino_plugin/build/": "written by the Rhino build (docs/rhino.md's packaging steps)",
    "rhino_plugin/components.ghx": "the file docs/rhino.md tells the user to save and add",
    "../../etc/passwd": "the path-traversal name safe_filename's doctest refuses",
    "../sites/ntc_site.json": "a search spec's ranking.site as docs/api.md's doctest prints it, "
    "relative to the spec's folder (examples/specs/)",
}
#: A path: folders joined by ``/``, optionally ``./`` or ``../`` first.
PATH = re.compile(r"(?<![\w./@:-])((?:\.\./|\./)?(?:[\w.-]+/)+[\w.-]*)")
#: A Markdown file named on its own (``STYLE.md``).
BARE_MD = re.compile(r"(?<![\w./-])([A-Z][A-Z_]+\.md)\b")
#: Top-level entries of the repository.
TOP = {p.name for p in ROOT.iterdir() if p.name not in SKIP_DIRS}
#: Folders a short path may be cited from (``core/records.py``; ``records/README.md`` of the
#: examples, as the wheel holds them).
PACKAGES = [
    ROOT / n for n in ("solver_service", "shared_schema", "cad_maths", "rockmech", "examples")
]


def _cited_in() -> list[Path]:
    out = []
    for path in sorted(ROOT.rglob("*")):
        rel = path.relative_to(ROOT)
        if SKIP_DIRS & set(rel.parts) or rel.parts[0].endswith(".egg-info"):
            continue
        if rel.name in ("CHANGELOG.md", "test_cited_paths.py"):  # history; this test's cases
            continue
        if path.suffix in (".py", ".md") and path.is_file():
            out.append(path)
    return out


FILES = _cited_in()


def _allowed(path: str) -> bool:
    return any(path == k or path.startswith(k.rstrip("/") + "/") for k in NOT_IN_THE_TREE)


def citations(text: str) -> Iterator[str]:
    """Yield each path-like citation of a text (placeholders and URLs left out)."""
    for match in PATH.finditer(text):
        cited = match.group(1).rstrip(".,:;")
        end = match.end()
        if text[end : end + 1] in "<*{" and end < len(text):
            continue  # a placeholder follows: examples/specs/<name>.json
        if cited.startswith(("./", "/")) or "//" in cited:
            continue
        yield cited


def problems(source: Path, text: str) -> Iterator[str]:
    """Yield why each citation of ``text`` (the file ``source``) does not hold."""
    base = source.parent
    ups = [base, *[p for p in base.parents if p == ROOT or ROOT in p.parents]]
    for cited in citations(text):
        if _allowed(cited):
            continue
        if cited.startswith("../shared/") or cited == "../shared":
            yield f"{cited}: the shared folder is not part of a clone; say what it holds instead"
            continue
        first = cited.split("/")[0]
        if first in TOP:
            if not (ROOT / cited).exists():
                yield f"{cited}: no such file or folder in the repository"
        elif cited.startswith("../"):
            if not (base / cited).exists():
                yield f"{cited}: no such path beside {source.relative_to(ROOT)}"
        elif cited.endswith((".py", ".md")):
            if not any((d / cited).exists() for d in [*ups, *PACKAGES]):
                yield f"{cited}: no such file beside, above or in a package"
    for name in BARE_MD.findall(text):
        if not any((d / name).exists() for d in (ROOT, ROOT / "docs", base)):
            yield f"{name}: no such page in the repository"


def test_the_walk_reads_the_code_docs_and_tests() -> None:
    names = {p.relative_to(ROOT).as_posix() for p in FILES}
    assert {"CONTRIBUTING.md", "docs/architecture.md", "solver_service/core/records.py"} <= names
    assert "tests/test_architecture.py" in names and len(FILES) > 300


@pytest.mark.parametrize("source", FILES, ids=lambda p: p.relative_to(ROOT).as_posix())
def test_every_cited_path_exists(source: Path) -> None:
    found = list(problems(source, source.read_text(encoding="utf-8")))
    assert found == [], f"{source.relative_to(ROOT)} cites: {found}"


def test_the_check_finds_a_missing_file_the_shared_folder_and_a_page() -> None:
    source = ROOT / "solver_service" / "core" / "records.py"
    text = (
        "see docs/records.md and formats/csv.py; ``benchmarks/library_bound.py``, "
        "``core/nowhere.py``, the records of ../shared/data/records, STYLE.md and "
        "CONTRIBUTING.md; examples/specs/<name>.json; https://example.org/a/b.md"
    )
    assert list(problems(source, text)) == [
        "benchmarks/library_bound.py: no such file or folder in the repository",
        "core/nowhere.py: no such file beside, above or in a package",
        "../shared/data/records: the shared folder is not part of a clone; say what it holds "
        "instead",
        "STYLE.md: no such page in the repository",
    ]


def test_every_exception_is_still_cited() -> None:
    # an exception nobody cites any more leaves the list, so it cannot hide a new one
    texts = [p.read_text(encoding="utf-8") for p in FILES]
    for key in NOT_IN_THE_TREE:
        assert any(key.rstrip("/") in t for t in texts if "NOT_IN_THE_TREE" not in t), key
