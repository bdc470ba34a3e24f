"""A run's output folder: rockmech replaces its own files there, as a set, and nothing else.

The folder a user names with ``--out`` may hold anything: notes, field data, a whole
``~/Documents``. A run writes into it only the files it makes itself, and keeps a list of
them, with their SHA-256 and the command that wrote them, in a small manifest,
``<out>/.rockmech/manifest.json``. The next run of the same command into the same folder
replaces those files and removes the ones it no longer writes, **only where they are still as
rockmech wrote them**; the files of other commands stay (a ``rockmech envelope`` run into the
folder of a ``rockmech history`` run keeps the history's files), and every other file and
folder is left byte for byte as it was.

How a run is written (``run_folder``):

1. The run writes into a fresh stage folder, ``<out>/.rockmech/stage-<pid>-<token>/``. Stage
   folders of runs that died are removed first; a live one is never touched (each stage
   holds an operating-system lock on its ``.lock`` file while its run lives).
2. When the block ends without error the run takes the folder's commit lock
   (``<out>/.rockmech/lock``) and checks that no file it is about to write is someone
   else's: a file that is not in the manifest, or that was changed after rockmech wrote
   it, is never replaced. The run then fails with one line naming the file, and the folder
   is left as it was.
3. A journal (``<out>/.rockmech/journal.json``) records the swap before it starts. Each old
   file is kept in a backup folder (a hard link, or a copy), each new file is renamed over
   its old one (atomically), the old files the run no longer writes go to the backup, and
   last the new manifest is written: **that write is the commit point**.
4. Whatever stops a swap (an error, Ctrl+C, a kill, a power cut), the next run into the
   folder, or this one on an error, reads the journal: before the commit point it puts
   every old file back and removes the new ones; after it, it finishes. A reader therefore
   finds the old set or the new set, never neither, and never a file half written.

An ``OSError`` (read-only folder, full disk, missing permission) becomes an ``InputError``
with one line naming the folder and the reason, which the command line prints as
``error: ...`` with exit status 2.
"""

from __future__ import annotations

import contextlib
import errno
import hashlib
import json
import os
import secrets
import shutil
import sys
import time
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any, Callable, Optional, Union

from shared_schema.atomic import remove_stale_temps, write_atomic
from shared_schema.errors import InputError
from shared_schema.version import __version__

if sys.platform == "win32":
    import msvcrt
else:
    import fcntl

__all__ = [
    "MANIFEST_NAME",
    "STATE_DIR",
    "check_file_target",
    "check_folder_target",
    "os_reason",
    "owned_files",
    "recover",
    "run_folder",
]

#: rockmech's own folder inside an output folder: the manifest, the journal, the stages.
STATE_DIR = ".rockmech"
#: The list of the files rockmech wrote in the folder, with their SHA-256.
MANIFEST_NAME = "manifest.json"
#: Written before a swap begins and removed when it has ended (either way).
JOURNAL_NAME = "journal.json"
#: Held (an operating-system lock) by the run that swaps its files in.
LOCK_NAME = "lock"
#: Format tag and version of the manifest and the journal.
MANIFEST_FORMAT = "rockmech-outputs"
MANIFEST_VERSION = 1
#: How long a run waits for another run's swap into the same folder [s]. A swap is a few
#: renames; the wait only matters when several runs finish into one folder at once.
LOCK_WAIT_S = 60.0
#: Poll interval of that wait [s].
LOCK_POLL_S = 0.05
#: Read size of the SHA-256 of a file [bytes].
_HASH_CHUNK = 1 << 20


def os_reason(exc: OSError) -> str:
    """Return a short reason for a write error: full disk, permission, read-only, ..."""
    if exc.errno == errno.ENOSPC:
        return "the disk is full"
    if exc.errno in (errno.EACCES, errno.EPERM):
        return "permission denied"
    if exc.errno == errno.EROFS:
        return "the file system is read-only"
    return exc.strerror or type(exc).__name__


def check_folder_target(out: Union[str, Path], field: str = "out") -> None:
    """Raise ``InputError`` if ``out`` exists and is not a folder (checked before a run)."""
    target = Path(out)
    if target.exists() and not target.is_dir():
        raise InputError(f"{target} is a file; give a folder for the run's outputs", field)
    state = target / STATE_DIR
    if state.exists() and not state.is_dir():
        raise InputError(
            f"{state} is a file, where rockmech keeps the list of its outputs; "
            "move it away or give another folder",
            field,
        )


def check_file_target(out: Union[str, Path], field: str = "out") -> None:
    """Check that a file can be written at ``out``, creating its missing parent folders.

    Every command that writes one file calls this before any work, so ``-o out/walls.json``
    works in a fresh folder and an impossible target fails at once.

    Parameters
    ----------
    out : path
        The file to be written (it may exist; it is replaced later).
    field : str
        Names the option in error messages.

    Raises
    ------
    InputError
        ``out`` is an existing folder, or its parent folder cannot be created (a file stands
        in the way, permission, read-only file system); one line naming the folder.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     check_file_target(Path(d) / "out" / "walls.json")
    ...     (Path(d) / "out").is_dir()
    True
    """
    target = Path(out)
    if target.is_dir():
        raise InputError(f"{target} is a folder; give a file name to write", field)
    parent = target.parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
    except (FileExistsError, NotADirectoryError):
        # A file where a folder must go: name it rather than print "File exists".
        blocker = next((p for p in (parent, *parent.parents) if p.is_file()), parent)
        raise InputError(f"cannot create folder {parent}: {blocker} is a file", field) from None
    except OSError as exc:
        raise InputError(f"cannot create folder {parent}: {os_reason(exc)}", field) from None


# --- locks: held by a live process, released by the system when it dies ---------------------


def _try_lock(handle: IO[bytes]) -> bool:
    """Take an exclusive lock on an open file without waiting; return whether it was taken."""
    try:
        if sys.platform == "win32":
            handle.seek(0)
            msvcrt.locking(handle.fileno(), msvcrt.LK_NBLCK, 1)
        else:
            fcntl.flock(handle.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        return False
    return True


@contextlib.contextmanager
def _locked(path: Path, wait_s: float, what: str, field: str) -> Iterator[None]:
    """Hold the lock file ``path`` for the block, waiting up to ``wait_s`` for another run."""
    handle = open(path, "a+b")  # held for the whole block
    try:
        deadline = time.monotonic() + wait_s
        while not _try_lock(handle):
            if time.monotonic() >= deadline:
                raise InputError(
                    f"another rockmech run is {what} {path.parent.parent}; wait for it to end, "
                    "or give another folder",
                    field,
                )
            time.sleep(LOCK_POLL_S)
        yield
    finally:
        handle.close()  # releases the lock


# --- the manifest and the journal -------------------------------------------------------------


def _sha256(path: Path) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(_HASH_CHUNK), b""):
            digest.update(chunk)
    return digest.hexdigest()


def _read_json(path: Path) -> dict[str, Any]:
    """Read one of rockmech's own JSON documents in the state folder ({} when absent)."""
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        return {}
    except (OSError, ValueError):
        raise InputError(
            f"{path} cannot be read; it is rockmech's list of its outputs in this folder. "
            "Remove the .rockmech folder to start afresh (rockmech will then replace none of "
            "the files there)",
            "out",
        ) from None
    if not isinstance(doc, dict) or doc.get("format") != MANIFEST_FORMAT:
        raise InputError(f"{path} is not a rockmech outputs list", "out")
    return doc


def _owners(out: Path) -> dict[str, str]:
    """Return which command wrote each of rockmech's files in ``out`` (relative path -> name).

    Files listed by a manifest that predates the record of commands have no entry: they
    belong to no command, so no run removes them unless it writes them anew.
    """
    owners = _read_json(out / STATE_DIR / MANIFEST_NAME).get("commands", {})
    return {str(k): str(v) for k, v in owners.items()} if isinstance(owners, dict) else {}


def owned_files(out: Union[str, Path]) -> dict[str, str]:
    """Return the files rockmech wrote in ``out``: relative POSIX path -> SHA-256.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     with run_folder(Path(d)) as tmp:
    ...         _ = (tmp / "result.json").write_text("{}")
    ...     sorted(owned_files(d))
    ['result.json']
    """
    files = _read_json(Path(out) / STATE_DIR / MANIFEST_NAME).get("files", {})
    return {str(k): str(v) for k, v in files.items()} if isinstance(files, dict) else {}


def _staged(stage: Path) -> dict[str, str]:
    """Return the files a run wrote into its stage (relative POSIX path -> SHA-256)."""
    found: dict[str, str] = {}
    for path in sorted(stage.rglob("*")):
        if path.is_file() and not path.is_symlink() and path.name != ".lock":
            found[path.relative_to(stage).as_posix()] = _sha256(path)
    return found


def _is_ours(path: Path, digest: str | None) -> bool:
    """Whether the file at ``path`` is rockmech's own, as rockmech wrote it."""
    try:
        return digest is not None and path.is_file() and _sha256(path) == digest
    except OSError:
        return False


def _remove_tree(path: Path) -> None:
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path, ignore_errors=True)
    else:
        with contextlib.suppress(FileNotFoundError):
            path.unlink()


def _keep_copy(src: Path, dst: Path) -> None:
    """Put a copy of ``src`` at ``dst``: a hard link where the file system has them."""
    dst.parent.mkdir(parents=True, exist_ok=True)
    with contextlib.suppress(FileNotFoundError):
        dst.unlink()
    try:
        os.link(src, dst)
    except OSError:
        shutil.copy2(src, dst)


def _prune_empty(folder: Path, top: Path) -> None:
    """Remove ``folder`` and its parents up to (not including) ``top`` while they are empty."""
    while folder != top and top in folder.parents:
        try:
            folder.rmdir()
        except OSError:
            return
        folder = folder.parent


def _roll_back(out: Path, journal: dict[str, Any]) -> None:
    """Undo a swap that did not reach its commit point: the old files back, the new ones out."""
    state = out / STATE_DIR
    backup = state / str(journal.get("backup", ""))
    new: dict[str, str] = journal.get("new", {})
    old: dict[str, str] = journal.get("old", {})
    for name in (*new, *(o for o in old if o not in new)):
        kept = backup / name
        target = out / name
        if kept.is_file():
            target.parent.mkdir(parents=True, exist_ok=True)
            os.replace(kept, target)
        elif name not in old and _is_ours(target, new.get(name)):
            target.unlink()
            _prune_empty(target.parent, out)


def recover(out: Union[str, Path], field: str = "out") -> str:
    """End a swap into ``out`` that a killed run left half done; return what was done.

    Before the commit point the old files are put back and the new ones removed
    (``"rolled back"``); after it the swap is finished (``"completed"``); with no swap
    pending nothing is done (``""``). Stage folders of runs that ended are removed.
    Every run into ``out`` calls this first; it is safe to call at any time.

    Raises
    ------
    InputError
        The folder cannot be written (permission, read-only, full disk).
    """
    state = Path(out) / STATE_DIR
    if not state.is_dir():
        return ""
    try:
        with _locked(state / LOCK_NAME, LOCK_WAIT_S, "writing to", field):
            done = _recover_locked(Path(out))
            _remove_dead_stages(state)
    except OSError as exc:
        raise InputError(f"cannot write to {out}: {os_reason(exc)}", field) from None
    return done


def _recover_locked(out: Path) -> str:
    """``recover`` with the folder's lock held (so no swap is in progress)."""
    state = out / STATE_DIR
    journal = _read_json(state / JOURNAL_NAME)
    if not journal:
        return ""
    manifest = _read_json(state / MANIFEST_NAME)
    committed = manifest.get("run") == journal.get("run")
    if not committed:
        _roll_back(out, journal)
    for key in ("backup", "stage"):
        if journal.get(key):
            _remove_tree(state / str(journal[key]))
    (state / JOURNAL_NAME).unlink()
    return "completed" if committed else "rolled back"


def _remove_dead_stages(state: Path) -> None:
    """Remove the stage and backup folders whose run has ended (their lock is free)."""
    remove_stale_temps(state)  # a journal or manifest write that was killed half way
    for path in state.iterdir():
        if not path.is_dir() or not path.name.startswith(("stage-", "backup-")):
            continue
        lock = path / ".lock"
        if path.name.startswith("backup-") or not lock.exists():
            # A backup outlives no swap (the journal names the one in progress) and a stage
            # gets its lock first thing: both are leftovers of a run that died.
            _remove_tree(path)
            continue
        try:
            handle = open(lock, "a+b")
        except OSError:
            continue
        try:
            free = _try_lock(handle)
        finally:
            handle.close()
        if free:
            _remove_tree(path)


def _conflicts(out: Path, new: dict[str, str], old: dict[str, str]) -> str:
    """Return why the new files cannot go into ``out`` ("" when they can)."""
    for name in new:
        target = out / name
        for parent in target.parents:
            if parent == out:
                break
            if parent.exists() and not parent.is_dir():
                return f"{parent} is a file where rockmech writes the folder {parent.name}/"
        if not target.exists() and not target.is_symlink():
            continue
        if target.is_dir() or target.is_symlink():
            return f"{target} is in the way (a folder or a link that rockmech did not write)"
        if name not in old:
            return (
                f"{target} was not written by rockmech (it is not in {STATE_DIR}/{MANIFEST_NAME}) "
                "and rockmech replaces only its own files"
            )
        if not _is_ours(target, old[name]):
            return f"{target} was changed after rockmech wrote it; rockmech keeps it as it is"
    return ""


def _commit(out: Path, stage: Path, token: str, field: str, command: str) -> list[str]:
    """Swap the stage's files into ``out`` as a set; return notes for the user.

    The files the earlier runs of ``command`` wrote and this run does not are removed where
    still as rockmech wrote them; the files of other commands stay, listed as theirs.
    """
    state = out / STATE_DIR
    notes: list[str] = []
    _recover_locked(out)
    every: dict[str, str] = dict(owned_files(out))
    owners = _owners(out)
    new = _staged(stage)
    old = {k: v for k, v in every.items() if k in new or owners.get(k) == command}
    kept_files = {k: v for k, v in every.items() if k not in old}
    kept_owners = {k: owners[k] for k in kept_files if k in owners}
    why = _conflicts(out, new, old)
    if why:
        raise InputError(f"{why}: move it away or give another folder; nothing was written", field)
    # Old files changed since rockmech wrote them are the user's now: left, and listed no more.
    for name in [o for o in old if o not in new]:
        if not _is_ours(out / name, old[name]):
            del old[name]
            if (out / name).exists():
                notes.append(f"{out / name} was changed after rockmech wrote it; left as it is")
    backup = f"backup-{os.getpid()}-{token}"
    journal = {
        "format": MANIFEST_FORMAT,
        "version": MANIFEST_VERSION,
        "run": token,
        "stage": stage.name,
        "backup": backup,
        "new": new,
        "old": old,
    }
    write_atomic(state / JOURNAL_NAME, json.dumps(journal, indent=1) + "\n")
    kept = state / backup
    kept.mkdir()
    try:
        for name in new:
            target = out / name
            if name in old and target.is_file():
                _keep_copy(target, kept / name)
            target.parent.mkdir(parents=True, exist_ok=True)
            os.replace(stage / name, target)
        for name in old:
            if name not in new and (out / name).is_file():
                (kept / name).parent.mkdir(parents=True, exist_ok=True)
                os.replace(out / name, kept / name)
                _prune_empty((out / name).parent, out)
        done = {
            "format": MANIFEST_FORMAT,
            "version": MANIFEST_VERSION,
            "rockmech": __version__,
            "run": token,
            "files": {**kept_files, **new},
            "commands": {**kept_owners, **dict.fromkeys(new, command)},
        }
        write_atomic(state / MANIFEST_NAME, json.dumps(done, indent=1) + "\n")  # commit point
    except BaseException:
        with contextlib.suppress(OSError, InputError):
            _recover_locked(out)
        raise
    _recover_locked(out)  # the commit is made: this removes the backup and the journal
    return notes


@contextlib.contextmanager
def run_folder(
    out: Union[str, Path],
    field: str = "out",
    on_note: Optional[Callable[[str], None]] = None,
    command: str = "",
) -> Iterator[Path]:
    """Yield a fresh stage folder to write a run into; on success its files go into ``out``.

    Only the files the run writes, and the files earlier runs of the same command wrote
    there (listed in the folder's manifest and unchanged since), are replaced or removed:
    everything else in ``out`` stays as it was, the other commands' outputs included. See
    the module's docstring for how the set is swapped.

    Parameters
    ----------
    out : path
        The run's output folder (created if missing; ``.`` works).
    field : str
        Names the option in error messages.
    on_note : callable, optional
        Called with each note for the user (a swap a killed run left and that this run
        ended, an old output the user changed and that is left as it is). Without it the
        notes are issued as ``UserWarning``.
    command : str
        The command that writes the run (``"search"``, ``"history"``, ...), recorded in the
        manifest: a run replaces the set its own command wrote there before and keeps the
        other commands' files.

    Raises
    ------
    InputError
        ``out`` is a file; a file the run would write is not rockmech's own, or was changed
        after rockmech wrote it; writing failed (read-only, full disk, permission). One line;
        the folder is left as it was.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     _ = (Path(d) / "notes.txt").write_text("mine")
    ...     with run_folder(Path(d)) as tmp:
    ...         _ = (tmp / "result.json").write_text("{}")
    ...     sorted(p.name for p in Path(d).iterdir())
    ['.rockmech', 'notes.txt', 'result.json']
    """
    target = Path(out)
    check_folder_target(target, field)
    note = on_note or (lambda text: warnings.warn(text, UserWarning, stacklevel=4))
    state = target / STATE_DIR
    token = secrets.token_hex(6)
    stage = state / f"stage-{os.getpid()}-{token}"
    try:
        state.mkdir(parents=True, exist_ok=True)
        # The stage is made and locked with the folder's lock held, so that no other run
        # takes it for the stage of a run that died.
        with _locked(state / LOCK_NAME, LOCK_WAIT_S, "writing to", field):
            done = _recover_locked(target)
            _remove_dead_stages(state)
            stage.mkdir()
            stage_lock = open(stage / ".lock", "a+b")  # held for the whole run
            _try_lock(stage_lock)
    except (FileExistsError, NotADirectoryError):
        blocker = next((p for p in (target, *target.parents) if p.is_file()), target)
        raise InputError(f"cannot create folder {target}: {blocker} is a file", field) from None
    except OSError as exc:
        raise InputError(f"cannot write to {target}: {os_reason(exc)}", field) from None
    if done:
        note(f"{target}: the outputs of a run that was stopped while writing them were {done}")
    notes: list[str] = []
    try:
        yield stage
        with _locked(state / LOCK_NAME, LOCK_WAIT_S, "writing to", field):
            notes = _commit(target, stage, token, field, command)
    except OSError as exc:
        raise InputError(f"cannot write to {target}: {os_reason(exc)}", field) from None
    finally:
        stage_lock.close()
        _remove_tree(stage)
    for text in notes:
        note(text)
