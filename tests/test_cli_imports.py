"""The command line loads what the command needs (issue #38).

Each case runs the typer app in a fresh interpreter, in-process there, and then reads that
interpreter's ``sys.modules``: ``rockmech --help``, ``--version`` and a one-pulse ``rockmech
pulse`` must not load scipy.optimize (the envelopes' root finders), ``cad_maths`` (the CAD
readers and the search) or matplotlib (the plots). A command that needs them still loads
them when it runs, which the last cases check, so that the probe can see a heavy import.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: Packages the light commands must not load (a module or any of its submodules).
HEAVY = ("scipy.optimize", "cad_maths", "matplotlib")
#: What ``--help`` and ``--version`` do not load either: numba (and its LLVM), the solver.
NOT_FOR_VERSION = ("numba", "llvmlite", "solver_service.core.exact")
#: One two-sided pulse (eta given: a two-sided pulse without one is refused).
PULSE = ["pulse", "--p-eq", "2", "--lam", "0.2", "--a-p-g", "0.3", "--f-p", "1", "--eta", "0.9"]

# Runs the console script's main on argv in this fresh interpreter (as `rockmech` runs it: one
# command, then the process ends), then prints its exit code and, as JSON,
# the loaded modules that are one of HEAVY or inside one.
PROBE = """
import json, sys
from solver_service.cli import main
sys.argv[0] = "rockmech"
try:
    main()
    code = 0
except SystemExit as exc:
    code = exc.code
heavy = sorted(m for m in sys.modules for h in HEAVY if m == h or m.startswith(h + "."))
print(json.dumps({"code": code, "heavy": heavy}), file=sys.stderr)
"""


def _loaded(
    argv: list[str], cwd: Path = ROOT, heavy: tuple[str, ...] = HEAVY
) -> tuple[int, list[str], str]:
    """Run ``rockmech argv`` in a fresh interpreter: exit code, ``heavy`` modules, stdout."""
    code = f"HEAVY = {heavy!r}\n" + PROBE
    res = subprocess.run(
        [sys.executable, "-c", code, *argv], capture_output=True, text=True, cwd=cwd
    )
    last = res.stderr.strip().splitlines()[-1]
    found = json.loads(last)
    return found["code"], found["heavy"], res.stdout


@pytest.mark.parametrize("argv", [["--help"], ["--version"]], ids=["help", "version"])
def test_help_and_version_load_no_numba_and_no_solver(argv: list[str]) -> None:
    code, heavy, stdout = _loaded(argv, heavy=(*HEAVY, *NOT_FOR_VERSION))
    assert code == 0, stdout
    assert stdout.strip(), "the command printed nothing"
    assert heavy == []


def test_the_probe_sees_numba_where_a_command_loads_it() -> None:
    # rockmech kernels loads numba to check the kernels (the CPU included).
    code, heavy, stdout = _loaded(["kernels"], heavy=NOT_FOR_VERSION)
    assert code == 0, stdout
    assert "numba" in heavy and "llvmlite" in heavy


@pytest.mark.parametrize(
    "argv", [["--help"], ["--version"], PULSE], ids=["help", "version", "pulse"]
)
def test_light_commands_load_no_optimiser_cad_or_plotting(argv: list[str]) -> None:
    code, heavy, stdout = _loaded(argv)
    assert code == 0, stdout
    assert stdout.strip(), "the command printed nothing"
    assert heavy == []


def test_the_pulse_command_still_answers() -> None:
    # p_eq = 2 rad/s, lam = 0.2, a_p = 0.3 g at 1 Hz: Omega = 2 pi / 2 = pi and A = 0.3 / 0.2.
    code, _, stdout = _loaded(PULSE)
    assert code == 0
    assert "Omega = 3.142, A = 1.5" in stdout


def test_the_boundary_loads_the_exact_kernels_but_no_optimiser() -> None:
    # rockmech boundary runs the exact kernels (numba); the envelopes no longer load the
    # pulse spectrum's root finder (scipy.optimize) with the module.
    code, heavy, stdout = _loaded(
        ["boundary", "--omega", "5", "--eta", "0.9"], heavy=(*HEAVY, "numba")
    )
    assert code == 0, stdout
    assert "numba" in heavy
    assert [m for m in heavy if m.split(".")[0] != "numba"] == []


@pytest.mark.slow  # the quick loop's budget: the whole suite (CI) runs it
def test_the_probe_sees_a_command_that_loads_the_optimiser(tmp_path: Path) -> None:
    # rockmech envelope on the bundled church: its mechanisms above ground need the pulse
    # spectrum's extrema (scipy.optimize's root finder), and it draws the envelopes.
    church = ROOT / "examples" / "constants" / "church.json"
    code, heavy, stdout = _loaded(["envelope", str(church), "--out", "out"], cwd=tmp_path)
    assert code == 0, stdout
    assert "scipy.optimize" in heavy and "matplotlib" in heavy


def test_the_probe_sees_a_command_that_loads_the_cad_readers(tmp_path: Path) -> None:
    # rockmech constants reads the scene with cad_maths; the refusal of a missing file comes
    # after its readers are loaded.
    argv = ["constants", "missing.3dm", "missing.json", "-o", "c.json"]
    code, heavy, _ = _loaded(argv, cwd=tmp_path)
    assert code == 2
    assert any(m == "cad_maths" or m.startswith("cad_maths.") for m in heavy)
    assert list(tmp_path.iterdir()) == []


def test_a_search_without_records_or_site_loads_no_solver_kernels_no_code_check_no_pyplot(
    tmp_path: Path,
) -> None:
    # The bundled façade's search, its ranking on the library's envelopes only: the exact
    # kernels (numba), the code check (workflows.assess) and pyplot stay unloaded; the figure
    # is drawn all the same (a Figure on an Agg canvas).
    spec = json.loads((ROOT / "examples/specs/search_facade.search.json").read_text())
    spec["ranking"] = {k: v for k, v in spec["ranking"].items() if k not in ("site", "records")}
    (tmp_path / "spec.json").write_text(json.dumps(spec))
    scene = str(ROOT / "examples/scenes/search_facade.3dm")
    heavy = ("numba", "solver_service.workflows.assess", "matplotlib.pyplot")
    code, found, stdout = _loaded(
        ["search", scene, "spec.json", "--out", "out"], cwd=tmp_path, heavy=heavy
    )
    assert code == 0, stdout
    assert found == []
    assert (tmp_path / "out" / "search.png").stat().st_size > 10_000


def test_one_pulse_runs_the_pure_python_kernels_without_numba() -> None:
    code, heavy, stdout = _loaded([*PULSE, "--json"], heavy=("numba", "llvmlite"))
    assert code == 0, stdout
    assert heavy == []
    assert json.loads(stdout)["method"] == "exact:python"


def test_a_pulse_of_restitution_near_one_loads_numba() -> None:
    # |eta| above kernel_cache.PLAIN_ETA_MAX: rocking that takes thousands of impacts to
    # settle, which the compiled kernels run faster than plain Python, numba's start included.
    argv = [*PULSE[:-1], "0.99", "--json"]
    code, heavy, stdout = _loaded(argv, heavy=("numba",))
    assert code == 0, stdout
    assert "numba" in heavy
    assert json.loads(stdout)["method"] == "exact:numba"


#: Pulses (p_eq, lam, eta, a_p_g, f_p, shape, one-sided): both signs, both shapes, impacts.
PLAIN_CASES = [
    (2.0, 0.2, 0.9, 0.3, 1.0, "sine", False),
    (2.0, 0.2, 0.95, 0.282, 0.32, "sine", False),
    (3.0, 0.15, 0.8, -0.4, 2.0, "cosine", False),
    (1.5, 0.25, 0.7, 0.2, 0.5, "sine", False),
    (2.0, 0.2, 0.95, 0.2002, 0.2, "cosine", False),
    (2.5, 0.1, -0.5, 0.25, 0.8, "sine", True),
]


@pytest.mark.parametrize("case", PLAIN_CASES, ids=[str(k) for k in range(len(PLAIN_CASES))])
def test_the_pure_python_pulse_gives_the_compiled_kernels_numbers_bit_for_bit(
    case: tuple[float, float, float, float, float, str, bool],
) -> None:
    import rockmech

    p_eq, lam, eta, a, f, shape, one_sided = case
    argv = ["pulse", "--p-eq", str(p_eq), "--lam", str(lam), "--eta", str(eta)]
    argv += ["--a-p-g", str(a), "--f-p", str(f), "--shape", shape, "--json"]
    argv += ["--one-sided"] if one_sided else []
    code, heavy, stdout = _loaded(argv, heavy=("numba",))
    assert code == 0 and heavy == [], stdout
    plain = json.loads(stdout)
    request = {"p_eq": p_eq, "lam": lam, "eta": eta, "a_p_g": a, "f_p": f, "shape": shape}
    compiled = rockmech.solve_pulse({**request, "one_sided": one_sided}).to_dict()
    assert (plain.pop("method"), compiled.pop("method")) == ("exact:python", "exact:numba")
    plain.pop("runtime_s")
    compiled.pop("runtime_s")
    assert plain == json.loads(json.dumps(compiled))


def test_the_app_called_in_a_longer_lived_process_keeps_numba() -> None:
    # Only the console script (one command, then the process ends) declines numba: a test or
    # a notebook calling the app keeps the compiled kernels for what it runs next.
    code = (
        "import sys\n"
        "from solver_service.cli import app\n"
        f"try:\n    app({[*PULSE, '--json']!r}, prog_name='rockmech')\n"
        "except SystemExit:\n    pass\n"
        "print('numba' in sys.modules, file=sys.stderr)\n"
    )
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert res.stderr.strip().splitlines()[-1] == "True", res.stderr
    assert json.loads(res.stdout)["method"] == "exact:numba"


def test_a_pulse_loads_no_other_request_model_and_no_masked_arrays() -> None:
    # The pulse request has its own module (shared_schema.pulse_request): a pulse loads
    # neither the other requests (shared_schema.api) nor the site file's or the retrofit's
    # models, nor numpy.ma (np.median's check for NaN).
    others = ("shared_schema.api", "shared_schema.site", "shared_schema.retrofit", "numpy.ma")
    code, heavy, stdout = _loaded(PULSE, heavy=others)
    assert code == 0, stdout
    assert heavy == []


# Runs argv in a fresh interpreter as the console script does (``main``: the application
# with the one command argv names), or with the whole application (``app``, the reference),
# both as one process that ends after the command.
WHOLE_OR_ONE = """
import sys
from solver_service.cli import CONSOLE, app, main
sys.argv[0] = "rockmech"
CONSOLE["process"] = True
main() if sys.argv.pop(1) == "one" else app()
"""


def _run(how: str, argv: list[str]) -> tuple[int, str, str]:
    res = subprocess.run(
        [sys.executable, "-c", WHOLE_OR_ONE, how, *argv], capture_output=True, text=True, cwd=ROOT
    )
    return res.returncode, res.stdout, res.stderr


@pytest.mark.parametrize(
    "argv",
    [
        PULSE,
        ["pulse", "--help"],
        [*PULSE, "--bogus"],
        ["pulse", "--p-eq", "x", "--a-p-g", "1", "--f-p", "1"],
        ["pulse", "--lam", "0.2", "--a-p-g", "0.3", "--f-p", "1", "--eta", "0.9"],
        ["boundary", "--omega", "2", "--eta", "0.9"],
        ["pulsee", "--f-p", "1"],
        ["library", "--help"],
        ["--version"],
    ],
    ids=[
        "pulse",
        "help",
        "bad-option",
        "bad-number",
        "no-p-eq",
        "boundary",
        "typo",
        "group",
        "version",
    ],
)
def test_the_console_script_answers_as_the_whole_application(argv: list[str]) -> None:
    # The console script builds the one command it runs; what it prints, on stdout and
    # stderr, and its exit status are the whole application's, help and errors included.
    one, whole = _run("one", argv), _run("whole", argv)
    assert one[1] or one[2], "the command printed nothing"
    assert one == whole
