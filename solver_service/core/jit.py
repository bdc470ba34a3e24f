"""The compiled kernels: whether they are active, where numba keeps them, building them ahead.

The exact solver's kernels (``_kernels`` and the modules it gathers) and the spectrum's loop
(``spectra``) are compiled by numba where it is installed (a dependency of the base install
on the platforms numba has wheels for). numba keeps the machine code in a cache on disk
(``cache=True``; beside the sources when that folder is writable, else in the user's cache
folder, or in ``NUMBA_CACHE_DIR``), so compilation is paid once per install, not per run.

Each solver path (``PATHS``) compiles the first time it runs, which takes from a few seconds
to about a minute on a laptop. ``first_use`` wraps the compiled call of each path: when the
path has not been built for these sources yet, it announces the compilation with one line
(``set_notifier``; stderr by default) before, and writes a stamp beside numba's cache after.
``precompile.build`` compiles every path ahead (``rockmech kernels``, the Docker image's
build, the service before it starts its workers). Without numba the same source runs as
plain Python, 10 to 100 times slower; the first kernel call of a process says so once, with
the reason.

Python 3.9-clean: Rhino 8 imports the solver through its flows (without numba).
"""

import contextlib
import json
import sys
import threading
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Dict, List, Optional, Set, Tuple

from shared_schema.atomic import write_atomic

from ._compile import JIT, JIT_REASON
from ._kernels import simulate_cells_logged
from .kernel_cache import PATHS, SOURCES, STAMP, numba_declined, stamp_key

__all__ = [
    "PATHS",
    "SOURCES",
    "STAMP",
    "KernelStatus",
    "first_use",
    "kernel_status",
    "notify",
    "set_notifier",
]

# PATHS (the solver paths compiled apart), SOURCES (those numba caches) and STAMP (a path's
# stamp beside numba's cache) live in kernel_cache, which rockmech --version reads without
# loading numba.

_LOCK = threading.Lock()
#: Paths checked in this process (a stamp is read once per process and path).
_CHECKED: Set[str] = set()
_STATE = {"said_python": False}


def _stderr_line(text: str) -> None:
    sys.stderr.write(text + "\n")
    sys.stderr.flush()


_NOTIFY: List[Callable[[str], None]] = [_stderr_line]


def set_notifier(fn: Optional[Callable[[str], None]]) -> None:
    """Send the progress and fallback lines to ``fn`` (None: stderr, the default)."""
    _NOTIFY[0] = fn if fn is not None else _stderr_line


def notify(line: str) -> None:
    """Send one progress or fallback line where ``set_notifier`` says (stderr by default)."""
    _NOTIFY[0](line)


@dataclass(frozen=True)
class KernelStatus:
    """Whether the compiled kernels are active, and which paths are built.

    Attributes
    ----------
    active : bool
        True when numba compiles the kernels; False when they run as plain Python.
    numba_version : str or None
        The installed numba's version (None without numba).
    reason : str or None
        Why the kernels are not compiled (None when they are).
    cache_dir : Path or None
        The folder numba keeps the compiled kernels in (None without numba).
    built : tuple of str
        The paths (``PATHS``) compiled for these sources and this numba, in that cache.
    """

    active: bool
    numba_version: Optional[str]
    reason: Optional[str]
    cache_dir: Optional[Path]
    built: Tuple[str, ...] = field(default=())

    def describe(self) -> str:
        """One line for ``rockmech --version``: active or not, and what is built where."""
        if not self.active:
            return (
                f"compiled kernels: not active ({self.reason}); the solver runs its "
                "pure-Python kernels, 10 to 100 times slower"
            )
        if len(self.built) == len(PATHS):
            state = "all built"
        elif self.built:
            state = f"built: {', '.join(self.built)}; the others compile on first use"
        else:
            state = (
                "not built yet: each path compiles on first use, or all at once by rockmech kernels"
            )
        return (
            f"compiled kernels: active (numba {self.numba_version}; {state}; "
            f"cache {self.cache_dir})"
        )


def _cache_dir() -> Optional[Path]:
    """Return the folder numba caches ``_kernels`` in (the one it chose for this install)."""
    if not JIT:
        return None
    cache = getattr(simulate_cells_logged, "_cache", None)
    path = getattr(cache, "_cache_path", None)
    return Path(path) if path else None


def _key() -> Dict[str, object]:
    """Return what numba's cache depends on: numba, Python, the CPU, the sources' stamps."""
    import numba
    from numba.core import config

    cpu = getattr(config, "CPU_NAME", None)
    if not cpu:
        import llvmlite.binding as llvm

        cpu = llvm.get_host_cpu_name()
    return stamp_key(numba.__version__, str(cpu))


def _stamp(path: str) -> Optional[Path]:
    folder = _cache_dir()
    return None if folder is None else folder / STAMP.format(path=path)


def _is_built(path: str, key: Dict[str, object]) -> bool:
    stamp = _stamp(path)
    if stamp is None:
        return False
    try:
        return bool(json.loads(stamp.read_text(encoding="utf-8")) == key)
    except (OSError, ValueError):
        return False


def kernel_status() -> KernelStatus:
    """Return whether the compiled kernels are active and which paths are built."""
    if not JIT:
        return KernelStatus(False, None, JIT_REASON, None)
    import numba

    key = _key()
    built = tuple(p for p in PATHS if _is_built(p, key))
    return KernelStatus(True, numba.__version__, None, _cache_dir(), built)


def first_use(path: str, backend: str = "auto") -> Optional[Callable[[], None]]:
    """Announce the compilation of ``path`` before its first compiled call.

    Cheap after the first call of a path in a process (one set lookup), so it can sit in
    front of every kernel call.

    Parameters
    ----------
    path : str
        One of ``PATHS``.
    backend : str
        The back end the caller asked for: only ``"auto"`` and ``"numba"`` compile; with
        ``"auto"`` and no numba, the pure-Python fallback is announced once per process.

    Returns
    -------
    callable or None
        Call it after the compiled call succeeded: it stamps ``path`` as built. None when
        there is nothing to stamp.
    """
    if path in _CHECKED or backend not in ("auto", "numba"):
        return None
    with _LOCK:
        todo = path not in _CHECKED
        _CHECKED.add(path)
        # a process that declined numba for one short run is not slowed down by it
        say_python = not JIT and not _STATE["said_python"] and not numba_declined()
        if say_python:
            _STATE["said_python"] = True
    if not JIT:
        if say_python:
            _NOTIFY[0](
                f"note: {JIT_REASON}, so the solver runs its pure-Python kernels, 10 to 100 "
                "times slower; pip install numba (on a platform it has wheels for) to compile them"
            )
        return None
    if not todo:
        return None
    key = _key()
    if _is_built(path, key):
        return None
    _NOTIFY[0](
        f"note: compiling the solver's kernels for {PATHS[path]}, once for this install "
        f"(seconds to a minute; kept in {_cache_dir()})"
    )
    return lambda: _write_stamp(path, key)


def _write_stamp(path: str, key: Dict[str, object]) -> None:
    stamp = _stamp(path)
    if stamp is not None:
        with contextlib.suppress(OSError):  # a read-only cache: numba recompiles anyway
            write_atomic(stamp, json.dumps(key, sort_keys=True))
