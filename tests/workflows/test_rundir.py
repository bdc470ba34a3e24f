"""A run replaces only rockmech's own files in its output folder, as a set; errors are one line.

The folder a user names may hold anything. These tests plant foreign files and folders in it,
run the real command line into it (killed at every file-system step of a run, the renames of
the swap included), and check that every foreign byte survives and that the folder then holds
the old outputs or the new ones, never neither.
"""

from __future__ import annotations

import errno
import json
import os
import signal
from pathlib import Path
from typing import Any

import pytest

from shared_schema.errors import InputError
from solver_service.workflows import rundir
from solver_service.workflows.rundir import STATE_DIR, owned_files, recover, run_folder

ROOT = Path(__file__).resolve().parents[2]
CHURCH = ROOT / "examples" / "constants" / "church.json"
RECORD = ROOT / "examples" / "records" / "elcentro_NS.dat"
RECT = ROOT / "examples" / "constants" / "rect_walls.json"

#: Files and folders that belong to the user: name -> bytes.
FOREIGN = {
    "README.txt": b"site visit 12 May: cracks at the NE corner\n",
    "notes/field.csv": b"x,y\n1,2\n",
    "notes/deep/photo.jpg": bytes(range(256)) * 4,
    ".hidden": b"\x00\x01",
}


def _plant(folder: Path) -> None:
    for name, data in FOREIGN.items():
        path = folder / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data)
    (folder / "empty_folder").mkdir(exist_ok=True)


def _assert_foreign_intact(folder: Path) -> None:
    for name, data in FOREIGN.items():
        assert (folder / name).read_bytes() == data, name
    assert (folder / "empty_folder").is_dir()


def _outputs(folder: Path) -> dict[str, bytes]:
    """The folder's files that are neither the user's nor rockmech's bookkeeping."""
    found = {}
    for path in folder.rglob("*"):
        rel = path.relative_to(folder).as_posix()
        if path.is_file() and rel not in FOREIGN and not rel.startswith(STATE_DIR + "/"):
            found[rel] = path.read_bytes()
    return found


def _names(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


def test_a_run_replaces_its_own_files_and_nothing_else(tmp_path: Path) -> None:
    _plant(tmp_path)
    with run_folder(tmp_path) as tmp:
        (tmp / "a.json").write_text("1")
        (tmp / "b.png").write_text("1")
        (tmp / "plots").mkdir()
        (tmp / "plots" / "c.png").write_text("1")
    with run_folder(tmp_path) as tmp:
        (tmp / "a.json").write_text("2")
    _assert_foreign_intact(tmp_path)
    # b.png and plots/c.png were the first run's own: the second run no longer writes them.
    assert _outputs(tmp_path) == {"a.json": b"2"}
    assert not (tmp_path / "plots").exists()
    assert owned_files(tmp_path) == {"a.json": rundir._sha256(tmp_path / "a.json")}


def test_a_foreign_or_changed_file_in_the_way_is_never_replaced(tmp_path: Path) -> None:
    (tmp_path / "a.json").write_text("the user's")
    with pytest.raises(InputError, match=r"a\.json was not written by rockmech.*nothing"):
        with run_folder(tmp_path) as tmp:
            (tmp / "a.json").write_text("1")
    assert (tmp_path / "a.json").read_text() == "the user's"
    (tmp_path / "a.json").unlink()
    with run_folder(tmp_path) as tmp:
        (tmp / "a.json").write_text("1")
        (tmp / "b.json").write_text("1")
    (tmp_path / "a.json").write_text("edited by the user")
    with pytest.raises(InputError, match=r"a\.json was changed after rockmech wrote it"):
        with run_folder(tmp_path) as tmp:
            (tmp / "a.json").write_text("2")
    assert (tmp_path / "a.json").read_text() == "edited by the user"
    # A changed file the next run no longer writes is kept, and is the user's from then on.
    notes: list[str] = []
    with run_folder(tmp_path, on_note=notes.append) as tmp:
        (tmp / "c.json").write_text("3")
    assert (tmp_path / "a.json").read_text() == "edited by the user"
    assert not (tmp_path / "b.json").exists()
    assert any("a.json was changed" in n for n in notes)
    assert set(owned_files(tmp_path)) == {"c.json"}


def test_a_failed_run_leaves_the_previous_one_untouched(tmp_path: Path) -> None:
    _plant(tmp_path)
    with run_folder(tmp_path) as tmp:
        (tmp / "a.json").write_text("1")
    with pytest.raises(RuntimeError), run_folder(tmp_path) as tmp:
        (tmp / "a.json").write_text("half")
        raise RuntimeError("plotting failed")
    _assert_foreign_intact(tmp_path)
    assert _outputs(tmp_path) == {"a.json": b"1"}
    assert _names(tmp_path / STATE_DIR) == ["lock", "manifest.json"]


def test_the_current_folder_works(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    _plant(tmp_path)
    monkeypatch.chdir(tmp_path)
    for text in ("1", "2"):
        with run_folder(Path(".")) as tmp:
            (tmp / "a.json").write_text(text)
    _assert_foreign_intact(tmp_path)
    assert _outputs(tmp_path) == {"a.json": b"2"}


def test_stages_of_dead_runs_are_removed_and_live_ones_kept(tmp_path: Path) -> None:
    state = tmp_path / STATE_DIR
    state.mkdir()
    dead = state / "stage-1-dead"
    dead.mkdir()
    (dead / "half.json").write_text("x")
    (dead / ".lock").write_bytes(b"")
    live = state / "stage-2-live"
    live.mkdir()
    holder = open(live / ".lock", "a+b")
    assert rundir._try_lock(holder)
    try:
        with run_folder(tmp_path) as tmp:
            (tmp / "a.json").write_text("1")
        assert _names(state) == ["lock", "manifest.json", "stage-2-live"]
    finally:
        holder.close()
    assert recover(tmp_path) == ""
    assert _names(state) == ["lock", "manifest.json"]


def test_an_unwritable_place_is_one_line_naming_it(tmp_path: Path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(InputError) as info, run_folder(blocker / "run"):
        pass
    message = str(info.value)
    assert "\n" not in message and str(blocker) in message and message.startswith("out: ")
    with pytest.raises(InputError, match="is a file"), run_folder(blocker):
        pass
    assert blocker.read_text() == "x"


def test_a_full_disk_in_the_swap_is_one_line_and_keeps_the_old_run(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _plant(tmp_path)
    with run_folder(tmp_path) as tmp:
        (tmp / "a.json").write_text("1")
        (tmp / "b.json").write_text("1")
    real = os.replace

    def full(src: object, dst: object) -> None:
        # The second file of the new set fails to go in; undoing the swap succeeds.
        if Path(str(dst)) == tmp_path / "b.json" and "stage-" in str(src):
            raise OSError(errno.ENOSPC, "No space left on device")
        real(src, dst)  # type: ignore[arg-type]

    monkeypatch.setattr(rundir.os, "replace", full)
    with pytest.raises(InputError, match="the disk is full"), run_folder(tmp_path) as tmp:
        (tmp / "a.json").write_text("2")
        (tmp / "b.json").write_text("2")
        (tmp / "c.json").write_text("2")
    monkeypatch.undo()
    _assert_foreign_intact(tmp_path)
    assert _outputs(tmp_path) == {"a.json": b"1", "b.json": b"1"}
    assert _names(tmp_path / STATE_DIR) == ["lock", "manifest.json"]


def test_targets_of_the_wrong_kind_are_named(tmp_path: Path) -> None:
    afile = tmp_path / "a.json"
    afile.write_text("{}")
    with pytest.raises(InputError, match=r"^out: .*a\.json is a file"):
        rundir.check_folder_target(afile)
    with pytest.raises(InputError, match=r"^output: .* is a folder"):
        rundir.check_file_target(tmp_path, "output")
    rundir.check_folder_target(tmp_path / "new")  # not there yet: fine
    rundir.check_file_target(afile)
    (tmp_path / "d").mkdir()
    (tmp_path / "d" / STATE_DIR).write_text("mine")
    with pytest.raises(InputError, match=r"^out: .*\.rockmech is a file"):
        rundir.check_folder_target(tmp_path / "d")
    message = rundir.os_reason(OSError(errno.EROFS, "Read-only file system"))
    assert message == "the file system is read-only"


def test_a_file_target_gets_its_parent_folders_or_one_line_why_not(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    target = tmp_path / "a" / "b" / "c.json"
    rundir.check_file_target(target, "output")
    assert (tmp_path / "a" / "b").is_dir() and not target.exists()
    rundir.check_file_target(target, "output")  # already there: fine
    (tmp_path / "f").write_text("x")
    with pytest.raises(InputError, match=r"^output: cannot create folder .*f/g: .*f is a file$"):
        rundir.check_file_target(tmp_path / "f" / "g" / "c.json", "output")
    with pytest.raises(InputError, match=r"^out: cannot create folder .*f: .*f is a file$"):
        rundir.check_file_target(tmp_path / "f" / "c.json")

    def denied(self: Path, *args: object, **kwargs: object) -> None:
        raise PermissionError(errno.EACCES, "Permission denied", str(self))

    monkeypatch.setattr(Path, "mkdir", denied)
    with pytest.raises(InputError, match=r"^out: cannot create folder .*new: permission denied$"):
        rundir.check_file_target(tmp_path / "new" / "c.json")


# --- every command that takes --out, into a folder holding the user's files -----------------

OUT_COMMANDS = {
    "envelope": ["envelope", str(CHURCH), "--n", "12"],
    "history": ["history", str(RECT), str(RECORD), "--scale", "0.5"],
    "record": ["record", str(RECORD), "--n", "20"],
    "ida": ["ida", str(RECT), str(RECORD), "--scales", "0.5:1:2", "--jobs", "1"],
    "demo": ["demo"],
}


@pytest.mark.slow
@pytest.mark.parametrize("command", sorted(OUT_COMMANDS))
def test_every_out_command_keeps_the_users_files(command: str, tmp_path: Path) -> None:
    from typer.testing import CliRunner

    from solver_service.cli import app

    _plant(tmp_path)
    argv = [*OUT_COMMANDS[command], "--out", str(tmp_path)]
    runner = CliRunner()
    first = runner.invoke(app, argv)
    assert first.exit_code == 0, first.output
    outputs = _outputs(tmp_path)
    assert outputs and set(outputs) == set(owned_files(tmp_path))
    again = runner.invoke(app, argv)  # the second run replaces the first run's files
    assert again.exit_code == 0, again.output
    _assert_foreign_intact(tmp_path)
    assert set(_outputs(tmp_path)) == set(outputs)


# --- a run killed at every step --------------------------------------------------------------


def _killed_run(k: int, argv: list[str]) -> tuple[int, int]:
    """Run the real command line in a forked child, killed (SIGKILL) at its K-th change.

    A change is a rename, link, removal, new folder or file opened for writing inside the
    output folder (the last argument). Returns the child's wait status and its count of
    changes (that count when it was not killed).
    """
    from solver_service.cli import app

    out = os.path.realpath(argv[-1])
    read_end, write_end = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: never returns into pytest
        code = 70
        try:
            os.close(read_end)
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, 1)
            os.dup2(devnull, 2)
            count = [0]

            def wrap(fn: Any, writes_only: bool = False) -> Any:
                def inner(*args: Any, **kwargs: Any) -> Any:
                    inside = bool(args) and os.path.realpath(os.fspath(args[0])).startswith(out)
                    writes = not writes_only or (
                        len(args) > 1 and args[1] & (os.O_WRONLY | os.O_RDWR)
                    )
                    if inside and writes:
                        if count[0] == k:
                            os.kill(os.getpid(), signal.SIGKILL)
                        count[0] += 1
                    return fn(*args, **kwargs)

                return inner

            for name in ("replace", "rename", "link", "unlink", "remove", "rmdir", "mkdir"):
                setattr(os, name, wrap(getattr(os, name)))
            os.open = wrap(os.open, writes_only=True)  # type: ignore[assignment]
            try:
                app(argv)
            except SystemExit as exc:
                code = exc.code if isinstance(exc.code, int) else 1
            os.write(write_end, str(count[0]).encode())
        finally:
            os._exit(code)
    os.close(write_end)
    with os.fdopen(read_end) as fh:
        steps = fh.read()
    _, status = os.waitpid(pid, 0)
    return status, int(steps or -1)


def _old_set(folder: Path) -> None:
    """Outputs of an earlier run: two the new run replaces and one it no longer writes."""
    with run_folder(folder, command="envelope") as tmp:
        (tmp / "envelope.json").write_text('{"old": true}')
        (tmp / "envelope.csv").write_text("old\n")
        (tmp / "legacy").mkdir()
        (tmp / "legacy" / "old_only.txt").write_text("old only\n")


@pytest.mark.slow  # one run killed at each of its file changes: a minute or more
@pytest.mark.skipif(not hasattr(os, "fork"), reason="kills a forked child (POSIX only)")
def test_a_run_killed_at_any_step_leaves_the_old_set_or_the_new_one(tmp_path: Path) -> None:
    argv = ["envelope", str(CHURCH), "--n", "12", "--fast", "--out"]  # the files, not the maths
    # Reference: the old set, and the new set as an uninterrupted run leaves it.
    ref = tmp_path / "ref"
    ref.mkdir()
    _plant(ref)
    _old_set(ref)
    old = _outputs(ref)
    status, steps = _killed_run(10**9, [*argv, str(ref)])
    assert os.WIFEXITED(status) and os.WEXITSTATUS(status) == 0, status
    new = _outputs(ref)
    assert set(new) == {"envelope.json", "envelope.csv", "envelope.png"} and new != old
    assert steps > 10
    seen = set()
    for k in range(steps):
        out = tmp_path / f"k{k}"
        out.mkdir()
        _plant(out)
        _old_set(out)
        status, _ = _killed_run(k, [*argv, str(out)])
        assert os.WIFSIGNALED(status) and os.WTERMSIG(status) == signal.SIGKILL, (k, status)
        _assert_foreign_intact(out)
        # What the next run does first, whatever command it is.
        recover(out)
        _assert_foreign_intact(out)
        now = _outputs(out)
        assert now in (old, new), (k, sorted(now))
        assert set(owned_files(out)) == set(now), k
        seen.add("new" if now == new else "old")
        assert _names(out / STATE_DIR) == ["lock", "manifest.json"], k
        # ... and a run after the kill completes.
        status, _ = _killed_run(10**9, [*argv, str(out)])
        assert os.WIFEXITED(status) and os.WEXITSTATUS(status) == 0, (k, status)
        _assert_foreign_intact(out)
        assert _outputs(out) == new, k
    assert seen == {"old", "new"}  # the kills fell on both sides of the commit point


def test_a_command_keeps_the_other_commands_outputs(tmp_path: Path) -> None:
    _plant(tmp_path)
    with run_folder(tmp_path, command="history") as tmp:
        (tmp / "history.json").write_text("h1")
        (tmp / "history.csv").write_text("h1")
    with run_folder(tmp_path, command="envelope") as tmp:
        (tmp / "envelope.json").write_text("e1")
    # The envelope run adds its file and keeps the history's.
    assert _outputs(tmp_path) == {
        "history.json": b"h1",
        "history.csv": b"h1",
        "envelope.json": b"e1",
    }
    # A second history run replaces the history's set (history.csv is no longer written)
    # and keeps the envelope's file.
    with run_folder(tmp_path, command="history") as tmp:
        (tmp / "history.json").write_text("h2")
    assert _outputs(tmp_path) == {"history.json": b"h2", "envelope.json": b"e1"}
    _assert_foreign_intact(tmp_path)
    owners = json.loads((tmp_path / STATE_DIR / "manifest.json").read_text())["commands"]
    assert owners == {"history.json": "history", "envelope.json": "envelope"}
    # A file one command wrote and another writes anew changes hands.
    with run_folder(tmp_path, command="envelope") as tmp:
        (tmp / "history.json").write_text("e2")
        (tmp / "envelope.json").write_text("e2")
    owners = json.loads((tmp_path / STATE_DIR / "manifest.json").read_text())["commands"]
    assert owners == {"history.json": "envelope", "envelope.json": "envelope"}
    assert set(owned_files(tmp_path)) == {"history.json", "envelope.json"}


def test_a_manifest_without_commands_loses_nothing(tmp_path: Path) -> None:
    """Files listed by an older manifest (no commands recorded) are kept unless rewritten."""
    with run_folder(tmp_path) as tmp:
        (tmp / "a.json").write_text("1")
        (tmp / "b.json").write_text("1")
    manifest = tmp_path / STATE_DIR / "manifest.json"
    doc = json.loads(manifest.read_text())
    del doc["commands"]
    manifest.write_text(json.dumps(doc))
    with run_folder(tmp_path, command="search") as tmp:
        (tmp / "a.json").write_text("2")
    assert _outputs(tmp_path) == {"a.json": b"2", "b.json": b"1"}
    assert set(owned_files(tmp_path)) == {"a.json", "b.json"}


def test_the_manifest_names_the_producing_version(tmp_path: Path) -> None:
    from rockmech import __version__

    with run_folder(tmp_path) as tmp:
        (tmp / "a.json").write_text("1")
    doc = json.loads((tmp_path / STATE_DIR / "manifest.json").read_text())
    assert doc["rockmech"] == __version__ and doc["format"] == "rockmech-outputs"
