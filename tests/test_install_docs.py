"""docs/install.md's table of extras is generated from pyproject.toml (#28).

One table: each install line, what it adds (the comment above the list in pyproject.toml)
and its packages. The test fails when the table and pyproject.toml disagree; run
``python tests/test_install_docs.py --write`` to regenerate it.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

import tomllib

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = ROOT / "pyproject.toml"
INSTALL_MD = ROOT / "docs" / "install.md"
BEGIN = (
    "<!-- extras table: generated from pyproject.toml by tests/test_install_docs.py "
    "(python tests/test_install_docs.py --write) -->"
)
END = "<!-- end of the extras table -->"


def _comment_above(text: str, key: str) -> str:
    """Join the comment lines right above ``key = [`` in pyproject.toml."""
    lines = text.splitlines()
    (at,) = [i for i, line in enumerate(lines) if line.startswith(f"{key} = [")]
    comment: list[str] = []
    for line in reversed(lines[:at]):
        if not line.startswith("#"):
            break
        comment.insert(0, line.lstrip("# ").rstrip())
    assert comment, f"pyproject.toml: no comment above {key} = [ (it is the table's text)"
    return " ".join(comment)


def _name(requirement: str) -> str:
    name = re.split(r"[<>=!~;\[ ]", requirement, maxsplit=1)[0]
    marker = requirement.split(";", 1)[1].strip() if ";" in requirement else ""
    return f"{name} (where it has wheels)" if marker and name == "numba" else name


def extras_table(text: str) -> str:
    """The markdown table of the base install and every extra, from pyproject.toml's text."""
    project = tomllib.loads(text)["project"]
    rows = [
        (
            "`pip install rockmech`",
            _comment_above(text, "dependencies"),
            ", ".join(_name(r) for r in project["dependencies"]),
        )
    ]
    for extra, reqs in project["optional-dependencies"].items():
        packages = []
        for req in reqs:
            inner = re.fullmatch(r"rockmech\[(.+)\]", req)
            packages.append(f"the extras {inner.group(1)}" if inner else _name(req))
        rows.append(
            (f"`pip install 'rockmech[{extra}]'`", _comment_above(text, extra), ", ".join(packages))
        )
    out = ["| install | adds | packages |", "|---|---|---|"]
    out += [f"| {a} | {b} | {c} |" for a, b, c in rows]
    return "\n".join(out)


def _block(doc: str) -> str:
    assert doc.count(BEGIN) == 1 and doc.count(END) == 1, "docs/install.md: table markers"
    return doc.split(BEGIN, 1)[1].split(END, 1)[0].strip()


def test_install_md_has_the_one_table_of_extras_generated_from_pyproject() -> None:
    doc = INSTALL_MD.read_text(encoding="utf-8")
    assert _block(doc) == extras_table(PYPROJECT.read_text(encoding="utf-8")), (
        "docs/install.md's extras table is out of date: python tests/test_install_docs.py --write"
    )
    # One table of extras only, naming every extra.
    assert doc.count("| install | adds | packages |") == 1
    extras = tomllib.loads(PYPROJECT.read_text())["project"]["optional-dependencies"]
    for extra in extras:
        assert f"rockmech[{extra}]" in _block(doc), extra


def test_the_table_text_is_the_pyproject_comment() -> None:
    table = extras_table(PYPROJECT.read_text(encoding="utf-8"))
    assert "| `pip install 'rockmech[report]'` | The assessment report's page" in table
    assert "numba (where it has wheels)" in table.splitlines()[2]


if __name__ == "__main__":
    if sys.argv[1:] != ["--write"]:
        raise SystemExit("usage: python tests/test_install_docs.py --write")
    doc = INSTALL_MD.read_text(encoding="utf-8")
    table = extras_table(PYPROJECT.read_text(encoding="utf-8"))
    head, rest = doc.split(BEGIN, 1)
    INSTALL_MD.write_text(f"{head}{BEGIN}\n{table}\n{END}{rest.split(END, 1)[1]}", encoding="utf-8")
    print(f"wrote the extras table of {INSTALL_MD}")
