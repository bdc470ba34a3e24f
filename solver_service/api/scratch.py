"""The service's temporary folders: one root per server, one folder per compute process in it.

Every compute process gets a private ``TMPDIR`` (uploads are written there under sanitised
names). They live under one root per server process, ``rockmech-service-*`` in the system's
temporary folder, which holds a file ``owner.pid`` with the server's process id. So that no
folder outlives what made it, however the server ends:

* the pool removes a process's folder when the process ends, and the root when it closes;
* a compute process whose server is gone (killed with SIGKILL, so it closed nothing) removes
  its own folder, and the root when it is the last one out (``leave``);
* a server starting removes the roots whose owner is no longer running (``sweep``): what a
  server and its processes killed together (the out-of-memory killer, a power cut) left.

Only folders this module made are ever removed: a root is recognised by its name prefix *and*
its ``owner.pid`` file, a process's folder by its name prefix inside such a root.

No third-party imports: the server process imports it, and it stays light.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import sys
import tempfile
from pathlib import Path
from typing import Optional

__all__ = ["OWNER_FILE", "ROOT_PREFIX", "WORKER_PREFIX", "leave", "make_root", "owner", "sweep"]

#: Name prefix of a server's root folder.
ROOT_PREFIX = "rockmech-service-"
#: Name prefix of a compute process's folder inside the root.
WORKER_PREFIX = "rockmech-worker-"
#: File in the root holding the server's process id (decimal, one line).
OWNER_FILE = "owner.pid"


def make_root(parent: Optional[str] = None) -> str:
    """Create this server's root folder (in ``parent``, default the system's) and own it.

    Returns
    -------
    str
        The root's path.
    """
    root = tempfile.mkdtemp(prefix=ROOT_PREFIX, dir=parent)
    Path(root, OWNER_FILE).write_text(f"{os.getpid()}\n", encoding="ascii")
    return root


def owner(root: Path) -> Optional[int]:
    """Return the process id that owns ``root``, or None when it is not a service root."""
    if not root.name.startswith(ROOT_PREFIX) or root.is_symlink() or not root.is_dir():
        return None
    try:
        text = (root / OWNER_FILE).read_text(encoding="ascii").strip()
    except (OSError, UnicodeDecodeError):
        return None
    return int(text) if text.isdigit() else None


def _running(pid: int) -> bool:
    """Whether process ``pid`` exists (a process of another user counts as running)."""
    if sys.platform == "win32":  # pragma: no cover - os.kill(pid, 0) would end it there
        return True  # no sweep: never remove what might still be in use
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def sweep(parent: Optional[str] = None) -> list[str]:
    """Remove the service roots in ``parent`` (default the system's) whose owner is gone.

    Returns
    -------
    list of str
        The roots removed.
    """
    folder = Path(parent or tempfile.gettempdir())
    removed = []
    with contextlib.suppress(OSError):
        for root in folder.glob(f"{ROOT_PREFIX}*"):
            pid = owner(root)
            if pid is not None and pid != os.getpid() and not _running(pid):
                shutil.rmtree(root, ignore_errors=True)
                removed.append(str(root))
    return removed


def leave(folder: str) -> None:
    """Remove a compute process's ``folder``, and its root once no process folder is left.

    Does nothing unless ``folder`` is a process folder inside a service root.
    """
    path = Path(folder)
    if not path.name.startswith(WORKER_PREFIX) or owner(path.parent) is None:
        return
    shutil.rmtree(path, ignore_errors=True)
    # Each process removes its own folder before it looks: the last one out sees none left.
    root = path.parent
    with contextlib.suppress(OSError):
        if not any(p.name.startswith(WORKER_PREFIX) for p in root.iterdir()):
            shutil.rmtree(root, ignore_errors=True)
