"""What is known of the compiled kernels without loading numba (``rockmech --version``).

Loading numba costs more than the rest of a light command (about twice the import of
numpy), so ``rockmech --version`` reads what it says from files instead: the installed
numba's version from its package metadata, the folder numba caches the kernels in (found by
numba's own rules for the two places a user can set or see: ``NUMBA_CACHE_DIR``, else the
``__pycache__`` folder beside the sources when it is writable), and the stamps that
``jit.first_use`` writes there once a solver path is compiled. A stamp counts as built when
rockmech's version, numba's, Python's and the kernel sources match (``stamp_key``); the CPU
it was built for is read from the stamps and stated, not checked (that needs LLVM, which is
part of loading numba). ``jit.kernel_status`` (``rockmech kernels``) loads numba and checks
everything, the CPU included.

Python 3.9-clean: Rhino 8 imports the solver through its flows (without numba).
"""

import hashlib
import importlib.util
import json
import os
import sys
from pathlib import Path
from typing import Dict, List, Optional, Tuple

from shared_schema.version import __version__

__all__ = [
    "KERNEL_SOURCES",
    "PATHS",
    "PLAIN_ETA_MAX",
    "PLAIN_REASON",
    "SOURCES",
    "STAMP",
    "cache_dir_guess",
    "numba_declined",
    "numba_version",
    "stamp_key",
    "version_line",
    "without_numba",
]

#: The kernel sources, compiled together (``_compile``'s docstring).
KERNEL_SOURCES = (
    "_compile.py",
    "_kernels.py",
    "_closed_form.py",
    "_stepping.py",
    "_batch_kernels.py",
    "_boundary_kernels.py",
)
#: Sources whose compiled code numba caches (their size and time stamp key its cache).
SOURCES = (*KERNEL_SOURCES, "spectra.py")
#: The solver paths compiled apart, each with what runs it.
PATHS: Dict[str, str] = {
    "simulate": "one run (simulate: pulses, records, time series)",
    "batch": "batches of runs (simulate_batch: histories, IDA)",
    "boundary": "overturning boundaries (boundary_curve: envelope --exact)",
    "library": "the overturning library (build_library: library build)",
    "spectrum": "response spectra (response_spectrum)",
}
#: Name of a path's stamp, written beside numba's cache once the path is compiled.
STAMP = "rockmech-kernels-{path}.json"
#: The kernel module whose cache folder holds the stamps (``jit._cache_dir``).
STAMPED_SOURCE = "_kernels.py"

#: Why the kernels run as plain Python in a process that declined numba (``without_numba``).
PLAIN_REASON = "numba not loaded (one short run costs less as plain Python than numba's start)"
#: Largest |eta| for which one pulse runs as plain Python (``rockmech pulse``). Rocking that
#: settles takes about ln(V_REST_REL) / ln|eta| impacts (1e-9: 404 at 0.95, 2060 at 0.99,
#: 20700 at 0.999), each some 80 us as Python: below 0.95 a pulse costs well under 0.2 s
#: there, less than loading numba and its cached kernels (about 1 s); above it numba runs.
PLAIN_ETA_MAX = 0.95

_HERE = Path(__file__).resolve().parent
#: Whether this process declined numba before its kernels were imported (``without_numba``).
_DECLINED = {"numba": False}


def without_numba() -> bool:
    """Run this process's solver kernels as plain Python, without loading numba.

    For a command that makes one short run (``rockmech pulse``): its results are those of the
    compiled kernels (the same code, uncompiled; ``exact.kernels``), its ``method`` says
    ``exact:python``, and it starts without numba's import and its cached kernels' load.

    Returns
    -------
    bool
        True when declined; False (nothing changes) when the kernels are already imported.
    """
    if "solver_service.core._compile" in sys.modules:
        return False
    _DECLINED["numba"] = True
    return True


def numba_declined() -> bool:
    """Return True when this process asked for plain-Python kernels (``without_numba``)."""
    return _DECLINED["numba"]


def numba_version() -> Optional[str]:
    """Return the installed numba's version, read without importing it (None: not installed)."""
    try:
        if importlib.util.find_spec("numba") is None:
            return None
    except (ImportError, ValueError):  # a broken or blocked entry in sys.modules
        return None
    # importlib.metadata here: rockmech --help imports this module, and needs none of it
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("numba")
    except PackageNotFoundError:  # a numba without metadata (a source tree)
        return None


def stamp_key(numba: str, cpu: str) -> Dict[str, object]:
    """Return what numba's cache of the kernels depends on, as written in each stamp.

    Parameters
    ----------
    numba : str
        numba's version.
    cpu : str
        The CPU the kernels are compiled for (LLVM's name, or ``NUMBA_CPU_NAME``).
    """
    sources = {}
    for name in SOURCES:
        st = os.stat(_HERE / name)
        sources[name] = [st.st_mtime, st.st_size]
    return {
        "rockmech": __version__,
        "numba": numba,
        "python": list(sys.version_info[:2]),
        "cpu": cpu,
        "sources": sources,
    }


def _writable(folder: Path) -> bool:
    return folder.is_dir() and os.access(folder, os.W_OK | os.X_OK)


def cache_dir_guess() -> Tuple[Optional[Path], str]:
    """Return the folder numba caches the kernels in, by its rules, and how it was found.

    Returns
    -------
    folder : Path or None
        ``NUMBA_CACHE_DIR``'s folder for the sources (numba's sub-folder name: the parent
        folder's name and the SHA-1 of its path), else the writable ``__pycache__`` beside
        the sources; None when numba would use the user-wide cache (which only numba's
        own path rules can name).
    how : str
        ``"NUMBA_CACHE_DIR"``, ``"beside the sources"`` or ``"user-wide"``.
    """
    user = os.environ.get("NUMBA_CACHE_DIR")
    if user:
        parent = str(_HERE)
        sub = "_".join([os.path.split(parent)[-1], hashlib.sha1(parent.encode()).hexdigest()])
        return Path(user) / sub, "NUMBA_CACHE_DIR"
    tree = _HERE / "__pycache__"
    if _writable(tree) or (not tree.exists() and _writable(_HERE)):
        return tree, "beside the sources"
    return None, "user-wide"


def _built_for(folder: Path, numba: str) -> Tuple[List[str], List[str]]:
    """Return the paths whose stamps in ``folder`` match (all but the CPU), and their CPUs."""
    built: List[str] = []
    cpus: List[str] = []
    for path in PATHS:
        try:
            stamp = json.loads((folder / STAMP.format(path=path)).read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue
        if not isinstance(stamp, dict):
            continue
        cpu = str(stamp.get("cpu"))
        if stamp == stamp_key(numba, cpu):
            built.append(path)
            if cpu not in cpus:
                cpus.append(cpu)
    return built, cpus


def version_line() -> str:
    """One line for ``rockmech --version`` about the compiled kernels, without loading numba.

    Examples
    --------
    >>> version_line().startswith("compiled kernels: ")
    True
    """
    numba = numba_version()
    if numba is None:
        return (
            "compiled kernels: not active (numba is not installed); the solver runs its "
            "pure-Python kernels, 10 to 100 times slower"
        )
    head = f"compiled kernels: numba {numba} installed, loaded when a solver path first runs"
    folder, how = cache_dir_guess()
    if folder is None:
        return (
            f"{head}; cache: numba's user-wide folder (rockmech kernels says which paths are "
            "built there and builds the others)"
        )
    built, cpus = _built_for(folder, numba)
    if len(built) == len(PATHS):
        state = "all built"
    elif built:
        state = f"built: {', '.join(built)}; the others compile on first use"
    else:
        state = "not built yet: each path compiles on first use, or all at once by rockmech kernels"
    cpu = f" for CPU {', '.join(cpus)}" if cpus else ""
    return f"{head} ({state}{cpu}; cache {folder}, {how})"
