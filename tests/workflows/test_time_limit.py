"""The command line's time limit: a run past it stops with TimeLimitExceeded, cleanly."""

from __future__ import annotations

import signal
import time
from pathlib import Path

import pytest

from shared_schema.errors import InputError
from solver_service.workflows import limits
from solver_service.workflows.limits import TimeLimitExceeded, active_time_limit, time_limit

pytestmark = pytest.mark.skipif(not hasattr(signal, "setitimer"), reason="needs setitimer")


def _spin(seconds: float) -> None:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        pass


def test_a_block_past_its_limit_is_stopped_near_the_limit() -> None:
    start = time.monotonic()
    with pytest.raises(TimeLimitExceeded) as exc, time_limit(0.2):
        _spin(120.0)
    # Stopped by the limit, not by the end of the block (no speed limit: a loaded machine
    # may be slow to deliver the signal).
    assert 0.2 <= time.monotonic() - start < 60.0
    assert str(exc.value) == (
        "time-limit: the run did not finish within its time limit of 0.2 s; give "
        "--time-limit with more seconds, or --no-limits to lift it"
    )
    # Not an Exception: a broad ``except Exception`` on the way cannot swallow it.
    assert not isinstance(exc.value, Exception)


def test_a_block_within_its_limit_runs_and_leaves_no_timer() -> None:
    before = signal.getsignal(signal.SIGALRM)
    with time_limit(5.0):
        assert active_time_limit() == 5.0
        _spin(0.05)
    assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)
    assert signal.getsignal(signal.SIGALRM) is before
    assert active_time_limit() == limits.CLI_BUDGET_S
    with time_limit(None):
        assert active_time_limit() == limits.CLI_BUDGET_S


def test_an_enclosing_timer_gets_its_remaining_time_back() -> None:
    fired: list[int] = []
    previous = signal.signal(signal.SIGALRM, lambda s, f: fired.append(s))
    try:
        signal.setitimer(signal.ITIMER_REAL, 0.6)
        with time_limit(5.0):
            _spin(0.1)
        remaining = signal.getitimer(signal.ITIMER_REAL)[0]
        assert 0.3 < remaining < 0.55
        _spin(0.7)
        assert fired == [signal.SIGALRM]
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def test_the_limit_waits_for_the_jit_compiler_to_return() -> None:
    # A function whose module is numba's: the limit must not be raised inside it (numba's
    # C code calls back into Python while compiling; an exception there crashed the process).
    scope = {"__name__": "numba.core.fake", "_spin": _spin}
    exec("def compile_kernel():\n    _spin(0.4)\n", scope)
    start = time.monotonic()
    with pytest.raises(TimeLimitExceeded), time_limit(0.1):
        scope["compile_kernel"]()
        _spin(120.0)
    assert 0.4 <= time.monotonic() - start < 60.0


def test_an_exception_wrapping_the_limit_is_reported_as_the_limit() -> None:
    with pytest.raises(TimeLimitExceeded), time_limit(0.1):
        try:
            _spin(5.0)
        except TimeLimitExceeded as exc:  # as numba's dispatcher does, with a SystemError
            raise SystemError("returned a result with an exception set") from exc


@pytest.mark.parametrize("bad", [0.0, -1.0, float("inf"), float("nan")])
def test_a_limit_that_is_not_a_positive_number_is_refused(bad: float) -> None:
    with pytest.raises(InputError, match="time-limit: must be a number of seconds > 0"):
        with time_limit(bad):
            pass


def test_the_up_front_estimate_uses_the_time_limit() -> None:
    from shared_schema.constants import ConstantsFile

    cf = ConstantsFile.model_validate(
        {"mechanisms": [{"id": "W", "eta": 0.9, "positive": {"p_eq": 500.0, "lam": 0.2}}]}
    )
    envelope = (0.1, 10.0, 400, True)  # about 1.3e8 closed-form steps
    limits.check_run(cf, envelope=envelope)  # 12 s at twice the measured rate: within 600 s
    with pytest.raises(InputError, match="more than its time limit of 1 s") as exc:
        with time_limit(1.0):
            limits.check_run(cf, envelope=envelope)
    assert "give --time-limit with more seconds, or --no-limits" in str(exc.value)


def test_a_command_profiled_with_cprofile_keeps_its_time_limit_and_its_profile(
    tmp_path: Path,
) -> None:
    # `python -m cProfile -m rockmech ...`: sys.getprofile() is the profiler object (not a
    # function); the time limit put it back with sys.setprofile and crashed with TypeError.
    import pstats
    import subprocess
    import sys

    ex = Path(__file__).resolve().parents[2] / "examples"
    prof = tmp_path / "retrofit.prof"
    args = [sys.executable, "-m", "cProfile", "-o", str(prof), "-m", "rockmech", "retrofit",
            str(ex / "constants" / "church_geometry.json"), "--site",
            str(ex / "sites" / "ntc_site.json"), "--spec",
            str(ex / "specs" / "church.retrofit.json"),
            "--out", str(tmp_path / "out"), "--time-limit", "300"]  # fmt: skip
    res = subprocess.run(args, capture_output=True, text=True, timeout=600)
    assert res.returncode == 0, res.stderr
    assert (tmp_path / "out" / "retrofit.json").is_file()
    # the profile still holds the retrofit's work, done inside the time limit
    names = {fn for (_, _, fn) in pstats.Stats(str(prof)).stats}
    assert "retrofit_doc" in names
