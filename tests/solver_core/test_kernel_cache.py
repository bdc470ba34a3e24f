"""``rockmech --version`` knows the compiled kernels without loading numba (#38).

``kernel_cache`` finds numba's cache folder by numba's rules and reads the stamps that
``jit.first_use`` writes; these tests hold it to what numba itself and ``jit.kernel_status``
(which load numba) say, in the dev install and in a fresh ``NUMBA_CACHE_DIR``.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numba

from solver_service.core import jit, kernel_cache

ROOT = Path(__file__).resolve().parents[2]

# Prints numba's own cache folder of the kernels and kernel_cache's, in a fresh interpreter.
FOLDERS = (
    "from solver_service.core import jit, kernel_cache\n"
    "print(jit._cache_dir()); print(kernel_cache.cache_dir_guess()[0])\n"
)


def test_the_cache_folder_found_without_numba_is_numbas_own() -> None:
    folder, how = kernel_cache.cache_dir_guess()
    assert how == "beside the sources"
    assert folder == jit._cache_dir()


def test_numba_cache_dir_is_followed_as_numba_follows_it(tmp_path: Path) -> None:
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    res = subprocess.run(
        [sys.executable, "-c", FOLDERS], capture_output=True, text=True, cwd=ROOT, env=env
    )
    assert res.returncode == 0, res.stderr
    numbas, ours = res.stdout.split()
    assert numbas == ours and Path(ours).parent == tmp_path


def test_the_version_line_counts_the_stamps_kernel_status_counts(tmp_path: Path) -> None:
    status = jit.kernel_status()
    assert status.active and status.cache_dir is not None
    assert kernel_cache.numba_version() == numba.__version__
    line = kernel_cache.version_line()
    assert "all built for CPU " + jit._key()["cpu"] in line
    # The same stamps in another folder, one of them for another numba: that path is not
    # built, the others are.
    for path in jit.PATHS:
        stamp = json.loads((status.cache_dir / jit.STAMP.format(path=path)).read_text())
        if path == "batch":
            stamp["numba"] = "0.0.1"
        (tmp_path / jit.STAMP.format(path=path)).write_text(json.dumps(stamp))
    built, cpus = kernel_cache._built_for(tmp_path, numba.__version__)
    assert built == [p for p in jit.PATHS if p != "batch"]
    assert cpus == [jit._key()["cpu"]]
    assert kernel_cache._built_for(tmp_path / "none", numba.__version__) == ([], [])


def test_without_numba_the_line_says_so() -> None:
    code = (
        "import sys; sys.modules['numba'] = None\n"
        "from solver_service.core.kernel_cache import version_line\n"
        "print(version_line())\n"
    )
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert res.returncode == 0, res.stderr
    assert res.stdout.startswith("compiled kernels: not active (numba is not installed)")


def test_numba_can_be_declined_only_before_the_kernels_are_imported() -> None:
    # This process has imported them (compiled): declining now changes nothing.
    from solver_service.core import exact

    assert exact.JIT
    assert kernel_cache.without_numba() is False
    assert kernel_cache.numba_declined() is False
    code = (
        "from solver_service.core import kernel_cache\n"
        "assert kernel_cache.without_numba()\n"
        "import sys\n"
        "from solver_service.core import exact, jit\n"
        "print(exact.JIT, 'numba' in sys.modules, jit.kernel_status().describe())\n"
    )
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert res.returncode == 0, res.stderr
    assert res.stdout.startswith("False False compiled kernels: not active (numba not loaded")
