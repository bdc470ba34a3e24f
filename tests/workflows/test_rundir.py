"""A run's output folder is written whole or not at all; write errors are one line."""

from __future__ import annotations

import errno
import os
import subprocess
import sys
from pathlib import Path

import pytest

from shared_schema.errors import InputError
from solver_service.workflows import rundir
from solver_service.workflows.rundir import run_folder, stale_folders


def _names(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


def test_a_finished_run_replaces_the_previous_one_whole(tmp_path: Path) -> None:
    out = tmp_path / "run"
    with run_folder(out) as tmp:
        (tmp / "a.json").write_text("1")
        (tmp / "b.png").write_text("1")
    with run_folder(out) as tmp:
        (tmp / "a.json").write_text("2")
    assert _names(tmp_path) == ["run"]
    assert _names(out) == ["a.json"]  # b.png of the first run is gone with it
    assert (out / "a.json").read_text() == "2"


def test_a_failed_run_leaves_the_previous_one_untouched(tmp_path: Path) -> None:
    out = tmp_path / "run"
    with run_folder(out) as tmp:
        (tmp / "a.json").write_text("1")
    with pytest.raises(RuntimeError), run_folder(out) as tmp:
        (tmp / "a.json").write_text("half")
        raise RuntimeError("plotting failed")
    assert _names(tmp_path) == ["run"]
    assert (out / "a.json").read_text() == "1"


def test_folders_of_dead_runs_are_removed_and_live_ones_kept(tmp_path: Path) -> None:
    dead = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"],
        capture_output=True,
        text=True,
        check=True,
    )
    stale = tmp_path / f".run.{int(dead.stdout)}.tmp"
    stale.mkdir()
    (stale / "half.json").write_text("x")
    live = tmp_path / f".run.{os.getppid()}.tmp"
    live.mkdir()
    assert stale_folders(tmp_path / "run") == [stale]
    with run_folder(tmp_path / "run") as tmp:
        (tmp / "a.json").write_text("1")
    assert _names(tmp_path) == sorted([live.name, "run"])


def test_an_unwritable_place_is_one_line_naming_it(tmp_path: Path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(InputError) as info, run_folder(blocker / "run"):
        pass
    message = str(info.value)
    assert "\n" not in message and str(blocker) in message and message.startswith("out: ")
    with pytest.raises(InputError, match="is a file"), run_folder(blocker):
        pass


def test_a_full_disk_at_commit_is_one_line_and_keeps_the_old_run(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "run"
    with run_folder(out) as tmp:
        (tmp / "a.json").write_text("1")
    real = os.replace
    failed: list[bool] = []

    def full(src: object, dst: object) -> None:
        # The new run's rename fails once; putting the old run back succeeds.
        if Path(str(dst)) == out and Path(str(src)).suffix == ".tmp" and not failed:
            failed.append(True)
            raise OSError(errno.ENOSPC, "No space left on device")
        real(src, dst)  # type: ignore[arg-type]

    monkeypatch.setattr(rundir.os, "replace", full)
    with pytest.raises(InputError, match="the disk is full"), run_folder(out) as tmp:
        (tmp / "a.json").write_text("2")
    monkeypatch.undo()
    assert _names(tmp_path) == ["run"]
    assert (out / "a.json").read_text() == "1"


def test_targets_of_the_wrong_kind_are_named(tmp_path: Path) -> None:
    afile = tmp_path / "a.json"
    afile.write_text("{}")
    with pytest.raises(InputError, match=r"^out: .*a\.json is a file"):
        rundir.check_folder_target(afile)
    with pytest.raises(InputError, match=r"^output: .* is a folder"):
        rundir.check_file_target(tmp_path, "output")
    rundir.check_folder_target(tmp_path / "new")  # not there yet: fine
    rundir.check_file_target(afile)
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
