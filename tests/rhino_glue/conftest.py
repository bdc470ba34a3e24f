"""A scripted Prompter over a real scene, and the headless CLI's constants as the reference."""

import json
import subprocess
import sys
from pathlib import Path
from typing import Any, Dict, List, Sequence, Tuple

import pytest

from rhino_plugin.flows.prompter import Cancelled

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "examples" / "scenes"
SPECS = ROOT / "examples" / "specs"

#: An answer that makes the prompter behave as if the user pressed Escape.
CANCEL = object()
#: A scripted answer meaning: press Enter and take the prompt's default.
ENTER = object()


class ScriptedPrompter:
    """Answers a flow's questions from a script of ``(method, answer)`` steps.

    Each call must be the next step's method (so a test also pins the order of the
    questions). Objects are scripted by name and answered by id, as Rhino does.
    """

    def __init__(self, scene: Any, steps: Sequence[Tuple[str, Any]]) -> None:
        self.scene = scene
        self.steps = list(steps)
        self.asked: List[Tuple[str, str]] = []
        self.messages: List[str] = []

    def _next(self, method: str, prompt: str) -> Any:
        self.asked.append((method, prompt))
        if not self.steps:
            raise AssertionError(f"unscripted {method}({prompt!r})")
        want, answer = self.steps.pop(0)
        assert want == method, f"expected {want}, the flow asked {method}({prompt!r})"
        if answer is CANCEL:
            raise Cancelled()
        return answer

    def _id(self, name: str) -> str:
        return str(self.scene.find(name)[0].id)

    def get_objects(
        self, prompt: str, kind: str = "solid", multiple: bool = True, optional: bool = False
    ) -> List[str]:
        names = self._next("get_objects", prompt)
        return [self._id(n) for n in names]

    def get_number(self, prompt: str, default: Any = None, optional: bool = False) -> Any:
        answer = self._next("get_number", prompt)
        if answer is ENTER:
            assert default is not None, f"{prompt!r} offers no default"
            return default
        return answer

    def get_line(self, prompt: str) -> Any:
        answer = self._next("get_line", prompt)
        return self._id(answer) if isinstance(answer, str) else answer

    def get_points(self, prompt: str, count: int) -> List[Any]:
        return list(self._next("get_points", prompt))

    def get_option(self, prompt: str, options: Sequence[str], default: int = 0) -> str:
        answer = self._next("get_option", prompt)
        assert answer in options, f"{answer!r} is not an option of {prompt!r}: {options}"
        return str(answer)

    def get_checkboxes(self, title: str, items: Sequence[str]) -> Dict[str, bool]:
        ticked = self._next("get_checkboxes", title)
        return {item: item in ticked for item in items}

    def get_file(self, prompt: str, extensions: Sequence[str], save: bool = False) -> str:
        return str(self._next("get_file", prompt))

    def message(self, text: str) -> None:
        self.messages.append(text)

    def done(self) -> bool:
        return not self.steps


@pytest.fixture(scope="session")
def scenes() -> Dict[str, Any]:
    """Example scenes read once with rhino3dm (Scene.from_3dm), by stem."""
    from cad_maths.scene_3dm import Scene

    cache: Dict[str, Any] = {}

    class _Lazy(dict):  # type: ignore[type-arg]
        def __missing__(self, stem: str) -> Any:
            cache[stem] = Scene.from_3dm(SCENES / f"{stem}.3dm")
            self[stem] = cache[stem]
            return cache[stem]

    return _Lazy()


@pytest.fixture(scope="session")
def cli_constants(tmp_path_factory: pytest.TempPathFactory) -> Any:
    """The headless ``rockmech constants SCENE SPEC`` output (parsed JSON), per scene stem."""
    out = tmp_path_factory.mktemp("cli")
    cache: Dict[str, Any] = {}

    def get(stem: str) -> Dict[str, Any]:
        if stem not in cache:
            target = out / f"{stem}.json"
            subprocess.run(
                [
                    sys.executable,
                    "-c",
                    "from solver_service.cli import app; app()",
                    "constants",
                    str(SCENES / f"{stem}.3dm"),
                    str(SPECS / f"{stem}.spec.json"),
                    "-o",
                    str(target),
                ],
                check=True,
                cwd=ROOT,
                capture_output=True,
            )
            doc = json.loads(target.read_text())
            cache[stem] = {m["id"]: m for m in doc["mechanisms"]}
        return cache[stem]

    return get
