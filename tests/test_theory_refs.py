"""Every citation of docs/theory.md in the repository resolves to a heading or an equation.

A citation is ``theory §2.3`` (``Theory`` at the start of a docstring) or
``docs/theory.md §2.3`` (optionally continued:
``theory §1.8, §6.3 and §10``, ranges ``§7.3–7.4``, ``§6-§7``, ``§6.3 (a)``) or
``theory Eq. 25`` / ``theory Eqs. 18-23`` (an equation tagged ``\\tag{25}``). Sections resolve
to the numbered headings of docs/theory.md (``## 2. ...``, ``### 2.3 ...``). The old private
reference (the same name in upper case) must not be cited any more.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterator
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
THEORY_MD = ROOT / "docs" / "theory.md"
SELF = Path(__file__).resolve()
#: File kinds searched for citations (the JSON files carry provenance strings and schemas).
SUFFIXES = {".py", ".md", ".json"}
#: Directories never searched: environments, caches, build output, generated results.
SKIP_DIRS = {".venv", "venv", ".git", "node_modules", "build", "dist", "out", "__pycache__"}
#: Files larger than this are data, not text that cites the theory [bytes].
MAX_BYTES = 2_000_000
#: The old reference's name, assembled so that this file does not cite it itself.
OLD_NAME = "THE" + "ORY"
#: Fewer citations than this means the parser (not the repository) is broken.
MIN_CITATIONS = 100

NUM = r"\d+(?:\.\d+)?"
START = re.compile(r"(?:docs/theory\.md|(?<![\w/.-])[Tt]heory)\s+(?=\(?\s*(?:§|\\u00a7|Eqs?\.))")
SEC = re.compile(rf"\(?\s*(?:§|\\u00a7)\s?({NUM})(?:\s?\([a-z]\))?")
EQ = re.compile(r"\(?\s*Eqs?\.\s*\(?(\d+)\)?")
SEP = re.compile(r"\s*(?:,|;|and|to|[-–])\s*")
RANGE_END = re.compile(rf"({NUM})(?![\w.])")
HEADING = re.compile(rf"^#{{2,4}}\s+({NUM})\.?\s", re.MULTILINE)
TAG = re.compile(r"\\tag\{(\d+)\}")


def headings(text: str) -> set[str]:
    """Section numbers of the numbered headings of a Markdown text."""
    return set(HEADING.findall(text))


def equations(text: str) -> set[int]:
    """Equation numbers tagged in a Markdown text."""
    return {int(n) for n in TAG.findall(text)}


def _expand(kind: str, first: str, last: str) -> list[tuple[str, str]]:
    if kind == "eq":
        return [("eq", str(n)) for n in range(int(first), int(last) + 1)]
    return [("sec", first), ("sec", last)]


def citations(text: str) -> list[tuple[str, str]]:
    """Return every ``(kind, number)`` cited, kind ``"sec"`` or ``"eq"``.

    Examples
    --------
    >>> citations("(theory §7.3–7.4; Eqs. 27-28)")
    [('sec', '7.3'), ('sec', '7.4'), ('eq', '27'), ('eq', '28')]
    >>> citations("docs/theory.md\\n  §3.2 and theory Eq. 25")
    [('sec', '3.2'), ('eq', '25')]
    """
    found: list[tuple[str, str]] = []
    for start in START.finditer(text):
        pos, kind, last = start.end(), "", ""
        while True:
            sec, eq = SEC.match(text, pos), EQ.match(text, pos)
            if sec:
                kind, last = "sec", sec.group(1)
                found.append((kind, last))
                pos = sec.end()
            elif eq:
                kind, last = "eq", eq.group(1)
                found.append((kind, last))
                pos = eq.end()
            else:
                break
            sep = SEP.match(text, pos)
            if not sep:
                break
            if sep.group(0).strip() in "-–":
                end = RANGE_END.match(text, sep.end())
                if end and not SEC.match(text, sep.end()):
                    found.extend(_expand(kind, last, end.group(1))[1:])
                    pos = end.end()
                    sep = SEP.match(text, pos)
                    if not sep:
                        break
            pos = sep.end()
    return found


def missing(text: str, theory: str) -> list[str]:
    """Citations in ``text`` that ``theory`` (the Markdown of docs/theory.md) does not have."""
    secs, eqs = headings(theory), equations(theory)
    out = []
    for kind, num in citations(text):
        if kind == "sec" and num not in secs:
            out.append(f"§{num}")
        if kind == "eq" and int(num) not in eqs:
            out.append(f"Eq. {num}")
    return out


def repo_files() -> Iterator[Path]:
    """Text files of the repository that may cite the theory."""
    for folder, dirs, names in os.walk(ROOT):
        dirs[:] = sorted(d for d in dirs if d not in SKIP_DIRS and not d.startswith("."))
        for name in sorted(names):
            path = Path(folder) / name
            if path.resolve() == SELF:  # its examples cite missing sections on purpose
                continue
            if path.suffix in SUFFIXES and path.stat().st_size <= MAX_BYTES:
                yield path


@pytest.fixture(scope="module")
def theory() -> str:
    return THEORY_MD.read_text(encoding="utf-8")


def test_theory_has_the_numbered_sections_the_code_relies_on(theory: str) -> None:
    secs = headings(theory)
    for top in range(11):
        assert str(top) in secs
    for sub in ("1.2", "1.8", "2.1", "2.4", "3.1", "3.4", "6.3", "6.5", "7.3", "7.4", "8.5"):
        assert sub in secs
    assert equations(theory) == set(range(1, 29))


def test_every_citation_resolves(theory: str) -> None:
    bad, count = [], 0
    for path in repo_files():
        text = path.read_text(encoding="utf-8", errors="replace")
        count += len(citations(text))
        bad += [f"{path.relative_to(ROOT)}: {m}" for m in missing(text, theory)]
    assert not bad, "citations of docs/theory.md that resolve to nothing:\n" + "\n".join(bad)
    assert count >= MIN_CITATIONS


def test_no_citation_of_the_old_reference_remains() -> None:
    old = re.compile(rf"\b{OLD_NAME}\b(?! OF LIABILITY)")
    bad = []
    for path in repo_files():
        if path.name.upper().startswith(("LICENSE", "LICENCE", "COPYING")):
            continue
        for n, line in enumerate(path.read_text(encoding="utf-8", errors="replace").splitlines()):
            if old.search(line):
                bad.append(f"{path.relative_to(ROOT)}:{n + 1}: {line.strip()}")
    assert not bad, "cite docs/theory.md instead:\n" + "\n".join(bad)


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("(theory §2.3)", []),
        ("(theory §11.19)", ["§11.19"]),
        ("docs/theory.md §2.9", ["§2.9"]),
        ("theory §1.8, §6.3 and §12", ["§12"]),
        ("theory §6-§13", ["§13"]),
        ("theory §7.3–7.9", ["§7.9"]),
        ("theory Eq. 29", ["Eq. 29"]),
        ("theory Eqs. 27-30", ["Eq. 29", "Eq. 30"]),
        ("theory §6.3 (a) and (b)", []),
        ("the theory of §99", []),
        ('"""Theory §3.9: docstring start', ["§3.9"]),
    ],
)
def test_a_citation_of_a_missing_section_or_equation_is_caught(
    theory: str, text: str, expected: list[str]
) -> None:
    assert missing(text, theory) == expected


def test_parser_examples() -> None:
    import doctest
    import sys

    failures, _ = doctest.testmod(sys.modules[__name__], verbose=False)
    assert failures == 0
