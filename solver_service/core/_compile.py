"""How the solver's kernels are compiled, and their pure-Python twins.

The kernel modules (``KERNEL_SOURCES``: ``_closed_form``, ``_stepping``, ``_batch_kernels``,
``_boundary_kernels``, gathered by ``_kernels``) are plain Python functions under the
decorators of this module: with numba installed each decorator compiles its function
(``cache=True``: numba keeps the machine code on disk), without numba each returns the
function unchanged.

numba keys the cache of a function by its own source file only, while the machine code of a
kernel holds the kernels it calls from the other files (numba issue #8396): an edit of
``_closed_form.py`` would leave the cached ``_stepping`` kernels running the old code. Each
compiled kernel's cache is therefore keyed by the content of every kernel source
(``key_by_sources``): an edit of any of them recompiles them all.

``python_twins`` gives the same functions uncompiled next to the compiled ones
(``exact.kernels("python")``): for each kernel module a module object holding the same
constants and, for each function, a new function of the same code whose globals are the
twin's, so a kernel calls the uncompiled version of every other kernel. No source is loaded
twice and no flag is injected; the compiled modules and numba's cache are untouched.

Python 3.9-clean: Rhino 8 imports the solver through its flows (without numba).
"""

import hashlib
import os
import threading
import types
from typing import Any, Callable, Dict, Optional, Tuple

from .kernel_cache import KERNEL_SOURCES, PLAIN_REASON, numba_declined

__all__ = [
    "JIT",
    "JIT_REASON",
    "TWIN_REASON",
    "inline",
    "jit",
    "jit_parallel",
    "key_by_sources",
    "leaf",
    "prange",
    "python_twins",
    "sources_stamp",
]

#: numba options of the helpers that allocate nothing (not in numba's type stubs).
LEAF_OPTIONS: Dict[str, Any] = {"_nrt": False, "error_model": "numpy"}
#: Why a twin's kernels run as plain Python (its ``JIT_REASON``).
TWIN_REASON = "compilation switched off"

Fn = Callable[..., Any]

# KERNEL_SOURCES: the kernel sources beside this module, compiled together (module
# docstring); listed in kernel_cache, which reads numba's cache without loading numba.

#: Why the kernels run as plain Python (None when numba compiles them).
JIT_REASON: Optional[str] = None
if numba_declined():  # a command making one short run (kernel_cache.without_numba)
    JIT = False
    JIT_REASON = PLAIN_REASON
else:
    try:  # numba is optional: without it the same code runs as plain Python.
        import numba as _numba

        JIT = True
    except ImportError as _exc:  # pragma: no cover - exercised where numba is missing
        # numba absent (no wheel for this platform), or present but unusable (its message).
        JIT = False
        JIT_REASON = (
            "numba is not installed"
            if getattr(_exc, "name", None) == "numba"
            else f"numba cannot be used: {_exc}"
        )


def sources_stamp(folder: str, names: Tuple[str, ...]) -> Optional[str]:
    """Return a digest of the contents of the files ``names`` in ``folder`` (None if unread)."""
    digest = hashlib.sha256()
    try:
        for name in names:
            with open(os.path.join(folder, name), "rb") as f:
                digest.update(name.encode() + b"\0" + f.read() + b"\0")
    except OSError:  # no sources to read (a frozen install): numba's own stamp stands
        return None
    return digest.hexdigest()


def key_by_sources(dispatcher: Any, stamp: Optional[str]) -> Any:
    """Key the on-disk cache of a numba ``dispatcher`` by ``stamp`` as well as its own file.

    Returns
    -------
    dispatcher
        The same object. Its cached code is loaded only while ``stamp`` (``sources_stamp``
        of every file its code comes from) is unchanged; ``tests/solver_core/test_jit.py``
        checks that the installed numba honours this.
    """
    cache_file: Any = getattr(getattr(dispatcher, "_cache", None), "_cache_file", None)
    if stamp is not None and hasattr(cache_file, "_source_stamp"):
        cache_file._source_stamp = (cache_file._source_stamp, stamp)
    return dispatcher


_STAMP = sources_stamp(os.path.dirname(os.path.abspath(__file__)), KERNEL_SOURCES) if JIT else None


def jit(fn: Fn) -> Fn:
    """Compile ``fn`` (numba, cached on disk, no GIL); unchanged without numba."""
    if not JIT:
        return fn
    return key_by_sources(_numba.njit(cache=True, nogil=True, error_model="numpy")(fn), _STAMP)  # type: ignore[no-any-return]


def jit_parallel(fn: Fn) -> Fn:
    """Compile ``fn`` with numba's parallel loops (``prange``); unchanged without numba."""
    if not JIT:
        return fn
    return key_by_sources(_numba.njit(cache=True, nogil=True, parallel=True)(fn), _STAMP)  # type: ignore[no-any-return]


def leaf(fn: Fn) -> Fn:
    """Compile a helper that allocates nothing, without reference counting of its arrays.

    The reference counting of its array arguments would otherwise cost more than the
    arithmetic of a step. Unchanged without numba.
    """
    if not JIT:
        return fn
    return key_by_sources(_numba.njit(cache=True, nogil=True, **LEAF_OPTIONS)(fn), _STAMP)  # type: ignore[no-any-return]


def inline(fn: Fn) -> Fn:
    """Compile a small helper of the per-sample and per-impact paths, inlined where called.

    Inlined in numba's IR: a call with array arguments costs more than its arithmetic.
    Unchanged without numba.
    """
    if not JIT:
        return fn
    compiled = _numba.njit(cache=True, nogil=True, inline="always", **LEAF_OPTIONS)(fn)
    return key_by_sources(compiled, _STAMP)  # type: ignore[no-any-return]


#: The parallel loop of ``jit_parallel`` kernels (``range`` when they run as Python).
prange: Any = _numba.prange if JIT else range

_LOCK = threading.Lock()
_TWINS: Dict[Tuple[str, ...], Dict[str, types.ModuleType]] = {}


def python_twins(*modules: types.ModuleType) -> Dict[str, types.ModuleType]:
    """Return the pure-Python twins of kernel ``modules``, by module name (built once).

    Parameters
    ----------
    *modules : module
        Kernel modules; every kernel they call must be defined in one of them.

    Returns
    -------
    dict of str to module
        For each module's ``__name__``, its twin: the same names, with every function of
        these modules (compiled or not) replaced by an uncompiled function of the same code
        whose globals are the twin's, each of these modules by its twin, ``prange`` by
        ``range``, ``JIT`` False and
        ``JIT_REASON`` ``TWIN_REASON``. Setting a twin's attribute (a test replacing a
        helper) changes what the twin's kernels call, never the compiled modules.
    """
    key = tuple(m.__name__ for m in modules)
    with _LOCK:
        if key not in _TWINS:
            _TWINS[key] = _build_twins(modules)
        return _TWINS[key]


def _build_twins(modules: Tuple[types.ModuleType, ...]) -> Dict[str, types.ModuleType]:
    names = {m.__name__ for m in modules}
    twins: Dict[str, types.ModuleType] = {}
    for mod in modules:
        twin = types.ModuleType(mod.__name__ + "_python", mod.__doc__)
        twin.__dict__.update({k: v for k, v in vars(mod).items() if k != "__name__"})
        twins[mod.__name__] = twin
    plain: Dict[int, types.FunctionType] = {}
    for twin in twins.values():
        for name, value in list(vars(twin).items()):
            fn = getattr(value, "py_func", value)  # a numba dispatcher keeps its Python function
            if isinstance(fn, types.FunctionType) and fn.__module__ in names:
                if id(fn) not in plain:
                    plain[id(fn)] = _rebind(fn, vars(twins[fn.__module__]))
                setattr(twin, name, plain[id(fn)])
            elif isinstance(value, types.ModuleType) and value.__name__ in names:
                setattr(twin, name, twins[value.__name__])
            elif JIT and value is _numba.prange:
                setattr(twin, name, range)
        twin.JIT = False  # type: ignore[attr-defined]
        twin.JIT_REASON = TWIN_REASON  # type: ignore[attr-defined]
    return twins


def _rebind(fn: types.FunctionType, namespace: Dict[str, Any]) -> types.FunctionType:
    """Return ``fn``'s code as a new function whose global names resolve in ``namespace``."""
    new = types.FunctionType(fn.__code__, namespace, fn.__name__, fn.__defaults__, fn.__closure__)
    new.__kwdefaults__ = fn.__kwdefaults__
    new.__qualname__ = fn.__qualname__
    new.__doc__ = fn.__doc__
    return new
