"""The modules of ``solver_service.core`` import each other without a circle (issue #13).

Every import counts, also those inside functions and ``importlib.import_module`` calls with
a literal name: a circle hidden in a lazy import is still a circle.
"""

from __future__ import annotations

import ast
from pathlib import Path

from solver_service.core import exact

CORE = Path(exact.__file__).resolve().parent
PACKAGE = "solver_service.core"


def _imports(path: Path) -> set[str]:
    """Core modules (short names) that the module at ``path`` imports."""
    out: set[str] = set()
    tree = ast.parse(path.read_text(encoding="utf-8"))
    for node in ast.walk(tree):
        names: list[str] = []
        if isinstance(node, ast.ImportFrom):
            if node.level == 1:
                base = node.module or ""
                names = [base] if base else [a.name for a in node.names]
            elif node.module is not None:
                if node.module == PACKAGE:
                    names = [a.name for a in node.names]
                elif node.module.startswith(PACKAGE + "."):
                    names = [node.module[len(PACKAGE) + 1 :]]
        elif isinstance(node, ast.Import):
            names = [
                a.name[len(PACKAGE) + 1 :] for a in node.names if a.name.startswith(PACKAGE + ".")
            ]
        elif (
            isinstance(node, ast.Call)
            and isinstance(node.func, ast.Attribute)
            and node.func.attr == "import_module"
            and node.args
            and isinstance(node.args[0], ast.Constant)
            and isinstance(node.args[0].value, str)
            and node.args[0].value.startswith(PACKAGE + ".")
        ):
            names = [node.args[0].value[len(PACKAGE) + 1 :]]
        out.update(n.split(".")[0] for n in names)
    return out


def _graph() -> dict[str, set[str]]:
    modules = {p.stem: p for p in CORE.glob("*.py") if p.stem != "__init__"}
    return {name: _imports(path) & set(modules) - {name} for name, path in modules.items()}


def _cycle(graph: dict[str, set[str]]) -> list[str]:
    """One import circle as a list of modules, or [] when the graph has none."""
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(node: str) -> list[str]:
        state[node] = 1
        stack.append(node)
        for nxt in sorted(graph[node]):
            if state.get(nxt) == 1:
                return [*stack[stack.index(nxt) :], nxt]
            if nxt not in state:
                found = visit(nxt)
                if found:
                    return found
        stack.pop()
        state[node] = 2
        return []

    for node in sorted(graph):
        if node not in state:
            found = visit(node)
            if found:
                return found
    return []


def test_cycle_finder_sees_a_circle() -> None:
    assert _cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert _cycle({"a": {"b"}, "b": set()}) == []


def test_exact_and_nonlinear_share_the_linearisation_module() -> None:
    graph = _graph()
    assert "linearisation" in graph["exact"]
    assert "exact" not in graph["linearisation"] and "nonlinear" not in graph["linearisation"]
    assert "nonlinear" not in graph["exact"]


def test_no_import_circle_in_core() -> None:
    assert _cycle(_graph()) == []
