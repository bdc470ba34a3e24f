"""The compiled kernels (#28): active in the base install, built ahead, announced once.

Compiling a solver path takes seconds to a minute: it happens once per install, with a
progress line, and ``rockmech --version`` says whether the kernels are compiled. Without
numba the pure-Python kernels run, and the first kernel call of a process says so once.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numba
import pytest
from typer.testing import CliRunner

from solver_service.cli import app
from solver_service.core import _compile, _kernels, jit

ROOT = Path(__file__).resolve().parents[2]
runner = CliRunner()


def _run(code: str, env: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        cwd=ROOT,
        env={**os.environ, **(env or {})},
        timeout=600,
    )


def test_the_dev_install_runs_compiled_kernels_built_ahead_by_the_test_session() -> None:
    status = jit.kernel_status()
    assert status.active and status.reason is None
    assert status.numba_version == numba.__version__
    # tests/conftest.py builds every path before the tests start.
    assert status.built == tuple(jit.PATHS)
    assert status.cache_dir is not None
    for path in jit.PATHS:
        stamp = json.loads((status.cache_dir / jit.STAMP.format(path=path)).read_text())
        assert stamp["numba"] == numba.__version__ and set(stamp["sources"]) == set(jit.SOURCES)
    line = status.describe()
    assert line.startswith(f"compiled kernels: active (numba {numba.__version__}; all built;")
    # --version reads the same stamps without loading numba, and names the CPU they were
    # built for instead of checking it (tests/solver_core/test_kernel_cache.py).
    res = runner.invoke(app, ["--version"])
    assert res.exit_code == 0
    assert res.stdout.splitlines()[1] == (
        f"compiled kernels: numba {numba.__version__} installed, loaded when a solver path "
        f"first runs (all built for CPU {jit._key()['cpu']}; cache {status.cache_dir}, "
        "beside the sources)"
    )
    res = runner.invoke(app, ["kernels"])
    assert res.exit_code == 0 and res.stdout == line + "\n"


def test_a_stamp_for_other_sources_or_another_numba_is_not_built(tmp_path: Path) -> None:
    status = jit.kernel_status()
    assert status.cache_dir is not None
    stamp = status.cache_dir / jit.STAMP.format(path="simulate")
    key = json.loads(stamp.read_text())
    assert jit._is_built("simulate", key)
    for field, value in (("numba", "0.0.1"), ("sources", {"_kernels.py": [0.0, 1]})):
        assert not jit._is_built("simulate", {**key, field: value})


@pytest.mark.slow
def test_first_use_of_a_path_in_a_fresh_cache_says_so_once_then_loads_it_silently(
    tmp_path: Path,
) -> None:
    # The spectrum path is the cheapest to compile (a second or two).
    code = (
        "import numpy as np\n"
        "from solver_service.core.spectra import response_spectrum\n"
        "acc = np.sin(np.linspace(0, 6, 61))\n"
        "a = response_spectrum(acc, 0.01, [0.5, 1.0]).psa\n"
        "b = response_spectrum(acc, 0.01, [0.5, 1.0], backend='numpy').psa\n"
        "assert np.allclose(a, b, rtol=1e-9), (a, b)\n"
        "response_spectrum(acc, 0.01, [0.7])\n"
        "from solver_service.core.jit import kernel_status\n"
        "print(kernel_status().built)\n"
    )
    env = {"NUMBA_CACHE_DIR": str(tmp_path)}
    first = _run(code, env)
    assert first.returncode == 0, first.stderr
    lines = first.stderr.strip().splitlines()
    assert len(lines) == 1, first.stderr
    assert lines[0].startswith("note: compiling the solver's kernels for response spectra")
    assert str(tmp_path) in lines[0]
    assert first.stdout.strip() == "('spectrum',)"
    assert list(tmp_path.rglob(jit.STAMP.format(path="spectrum")))
    again = _run(code, env)
    assert again.returncode == 0 and again.stderr == "", again.stderr


def test_without_numba_the_pure_python_kernels_run_and_say_so_once() -> None:
    # numba blocked, as on a platform without its wheel: the CLI still answers, with the
    # solver's numbers, and says once why it is slower.
    code = (
        "import sys; sys.modules['numba'] = None\n"
        "from typer.testing import CliRunner\n"
        "from solver_service.cli import app\n"
        "r = CliRunner()\n"
        # eta 0.99: a pulse the command would run compiled (kernel_cache.PLAIN_ETA_MAX)
        "args = ['pulse', '--p-eq', '2', '--lam', '0.2', '--eta', '0.99', '--a-p-g', '-0.61',"
        " '--f-p', '1.59', '--json']\n"
        "one, two = r.invoke(app, args), r.invoke(app, args)\n"
        "print(repr(one.stderr), repr(two.stderr), sep='\\n')\n"
        "print(r.invoke(app, ['--version']).stdout.splitlines()[1])\n"
        "import json; print(json.loads(one.stdout)['method'])\n"
    )
    res = _run(code)
    assert res.returncode == 0, res.stderr
    first, second, version, method = res.stdout.strip().splitlines()
    assert "note: numba is not installed, so the solver runs its pure-Python kernels" in first
    assert first.count("note:") == 1 and second == "''"
    assert version.startswith("compiled kernels: not active (numba is not installed)")
    assert method == "exact:python"


def test_the_build_rockmech_serve_runs_first_is_quiet_when_built_and_says_why_without_numba() -> (
    None
):
    code = "import sys; from solver_service.core.precompile import main; sys.exit(main())"
    built = _run(code)
    assert built.returncode == 0 and built.stderr == "", built.stderr
    blocked = _run("import sys; sys.modules['numba'] = None\n" + code)
    assert blocked.returncode == 1
    assert blocked.stderr.startswith("note: compiled kernels: not active (numba is not installed)")


CALLEE = "import numba\n\n\n@numba.njit(cache=True)\ndef f(x):\n    return x + {k}\n"
CALLER = """import os

import numba

from callee import f
from solver_service.core._compile import key_by_sources, sources_stamp


def g(x):
    return f(x) * 10


HERE = os.path.dirname(os.path.abspath(__file__))
g = key_by_sources(numba.njit(cache=True)(g), sources_stamp(HERE, ("callee.py", "caller.py")))
"""


def test_an_edit_of_a_kernel_that_a_cached_kernel_calls_recompiles_the_caller(
    tmp_path: Path,
) -> None:
    # numba keys a function's cache by its own file; the caller's machine code holds the
    # callee's, so without key_by_sources the caller would keep the old callee (#29).
    (tmp_path / "callee.py").write_text(CALLEE.format(k=1))
    (tmp_path / "caller.py").write_text(CALLER)
    code = (
        f"import sys; sys.path.insert(0, {str(tmp_path)!r})\n"
        "from caller import g\n"
        "print(g(1), sum(g.stats.cache_hits.values()))\n"
    )
    env = {"NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    runs = []
    for k in (1, 1, 2):
        (tmp_path / "callee.py").write_text(CALLEE.format(k=k))
        res = _run(code, env)
        assert res.returncode == 0, res.stderr
        runs.append(res.stdout.split())
    # compiled, then loaded from the cache, then compiled again with the new callee
    assert runs == [["20", "0"], ["20", "1"], ["30", "0"]]


def test_every_compiled_kernel_is_keyed_by_every_kernel_source() -> None:
    assert _compile._STAMP is not None
    kernels = [
        v
        for mod in _kernels.MODULES
        for v in vars(mod).values()
        if getattr(getattr(v, "py_func", None), "__module__", None) == mod.__name__
    ]
    assert len(kernels) > 50
    for k in kernels:
        assert k._cache._cache_file._source_stamp[1] == _compile._STAMP, k
