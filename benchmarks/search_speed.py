"""Speed of ``rockmech search`` (issue #31) on one core, against the issue's limits.

What is measured
----------------
The example scene ``examples/scenes/search_facade.3dm`` (a 3-storey façade with 6 windows
between 2 return walls, a back wall, two floors, a roof and a tie-bar) with its search spec
``examples/specs/search_facade.search.json`` (all families, both directions):

1. *search*: ``cad_maths.search.engine.run_search(scene, spec, lp=False)``: the building
   read from the scene's objects (walls as prisms, junctions, levels, ties) and every
   candidate enumerated and refined on the exact λ0; the ``.3dm`` file's own reading
   (``read_scene``) is reported beside it;
2. *constants of the top 50*: the same spec with a candidate hinge line every 0.25 m (at
   least 50 candidates), the 50 of least λ0 through the existing builder
   (``specs.build_candidates``: spec, cut meshes, constants, agreement);
3. *pulse ranking over 400 frequencies*: ``documents.envelope_doc`` of those 50 on 400
   log-spaced frequencies (the library, loaded once beforehand), the band scores and the
   sort;
4. *20 records*: ``workflows.search.scales_to_overturn`` of the 10 best ranked on 20 records
   (the shared PEER records where present, else copies of the bundled El Centro record
   shifted in time and scaled): each record's smallest overturning scale factor on a grid
   of 60, bisected to 1e-3;
5. *the LP check*: the global upper-bound programme (``lp.facade_lp_model`` + ``solve_lp``,
   HiGHS dual simplex) of the example façade at its own candidate lines, of the same façade
   cut by a line every ``LP_SPACING`` metres (about 300 macro-blocks), and of a two-block
   strip of 300 blocks (docs/search.md V1);
6. *the palazzo* (issue #37): a block of ``PALAZZO_WALLS`` walls round a courtyard, 4 storeys,
   40 windows, a floor in every room at each storey and a roof, good and poor junctions
   (``palazzo`` and ``palazzo_spec`` of ``examples/scenes/build_scenes.py``, written into a
   temporary folder): (a) its search alone, as in 1 (CPU on one thread against 3 s); (b) the
   whole command ``rockmech search <scene> <spec> --out <dir>`` in a subprocess, start-up,
   the global check, the builder, the ranking and the figure included (its wall-clock time
   against 6 s; the child's CPU time beside it), with the modules' bytecode caches as an
   installed rockmech has them (``_docs.command_env``).

How: one process, threads pinned to one (``*_NUM_THREADS=1`` before numpy loads, and
``core.exact.single_threaded`` around the records); one cold call of each stage, then the
best of ``REPEATS`` warm calls. Each stage's time is compared with the issue's limit in the
same run (ratio = measured / limit): CPU time, except for the whole command, which the issue
limits in wall-clock time.

Run ``.venv/bin/python benchmarks/search_speed.py``; it rewrites the ``search_speed`` section
of ``docs/benchmarks.md`` (``--no-docs`` to only print).
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402 (the thread pins above must come before numpy loads)
import json  # noqa: E402
import math  # noqa: E402
import resource  # noqa: E402
import shutil  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any, Callable  # noqa: E402

import numpy as np  # noqa: E402

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))

from _docs import DOC_MD, build_scenes, command_env, fmt_time, machine_info, write_section  # noqa: E402

from cad_maths.scenes import read_scene  # noqa: E402
from cad_maths.search.engine import run_search  # noqa: E402
from cad_maths.search.lp import facade_lp_model, solve_lp  # noqa: E402
from cad_maths.search.model import building_from_scene  # noqa: E402
from cad_maths.search.specs import build_candidates  # noqa: E402
from shared_schema.constants import ConstantsFile  # noqa: E402
from shared_schema.search import SearchSpec, parse_search_spec  # noqa: E402
from solver_service.core.envelope import OverturningLibrary  # noqa: E402
from solver_service.core.exact import single_threaded  # noqa: E402
from solver_service.workflows.documents import envelope_doc, log_grid  # noqa: E402
from solver_service.workflows.inputs import read_record  # noqa: E402
from solver_service.workflows.search import scales_to_overturn  # noqa: E402

SCENE = REPO / "examples" / "scenes" / "search_facade.3dm"
SPEC = REPO / "examples" / "specs" / "search_facade.search.json"
ELCENTRO = REPO / "examples" / "records" / "elcentro_NS.dat"
SHARED_RECORDS = REPO.parent / "shared" / "data" / "records"
#: Warm repeats of each stage (best of).
REPEATS = 3
#: Candidate hinge lines every this many metres for the 50 candidates [m].
SPACING_50 = 0.25
#: Spacings tried for the ~300-block check [m] (the largest count up to 300 is run).
LP_SPACINGS = (5.0, 4.0, 3.0, 2.5, 2.0, 1.5, 1.0, 0.75, 0.5)
#: The issue's limits [s].
LIMITS = {
    "search": 2.0,
    "constants": 3.0,
    "ranking": 0.1,
    "records": 2.0,
    "lp": 1.0,
    "palazzo": 3.0,
    "palazzo_cli": 6.0,
}
#: Stages whose limit is on the wall-clock time (the others: CPU time).
WALL_LIMITED = {"palazzo_cli"}
#: Runs of the whole command (the first is reported as the cold one; best of the others).
CLI_RUNS = 3
#: The example scenes' builder, which writes the palazzo.


def best_of(fn: Callable[[], Any], repeats: int = REPEATS) -> tuple[float, float, float, Any]:
    """Cold and best warm CPU time, best warm wall-clock time [s], and ``fn``'s result.

    The targets are judged on CPU time: on a shared machine the wall clock also counts the
    time other processes hold the core, while the CPU time of a process pinned to one thread
    is the work done on one core. The wall-clock time is reported beside it.
    """
    t = time.process_time()
    out = fn()
    cold = time.process_time() - t
    best = wall = math.inf
    for _ in range(repeats):
        t, w = time.process_time(), time.perf_counter()
        out = fn()
        best = min(best, time.process_time() - t)
        wall = min(wall, time.perf_counter() - w)
    return cold, best, wall, out


def records(n: int = 20) -> tuple[list[Any], str]:
    """Twenty records: the shared PEER files where present, else El Centro variants."""
    if SHARED_RECORDS.is_dir():
        files = sorted(p for p in SHARED_RECORDS.rglob("*.AT2"))[:n]
        if len(files) == n:
            return [read_record(p) for p in files], f"{n} PEER AT2 files of the shared folder"
    base = read_record(ELCENTRO)
    out = []
    for k in range(n):
        shift = 50 * k
        acc = np.roll(base.accel.acc, shift) * (0.8 + 0.02 * k)
        out.append(type(base).from_samples(acc, base.dt, units="m/s2", name=f"elcentro_{k}"))
    return out, f"{n} copies of the bundled El Centro 1940 N-S, shifted in time and scaled"


def main(argv: list[str] | None = None) -> int:
    """Run the stages, print the tables, write the docs section."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-docs", action="store_true", help="print only")
    args = parser.parse_args(argv)
    t_all = time.perf_counter()
    info = machine_info(("numpy", "scipy", "numba", "shapely", "manifold3d"))
    spec = parse_search_spec(SPEC.read_bytes(), SPEC.name)
    cold_read, read_s, read_w, scene = best_of(lambda: read_scene(SCENE))
    cold_search, search_s, search_w, res = best_of(lambda: run_search(scene, spec, lp=False))
    n_cands = len(res.candidates)
    evaluations = sum(c.n_evaluations for c in res.candidates)
    # 50 candidates: a hinge line every SPACING_50 m
    doc = spec.model_dump(exclude_unset=True)
    doc["candidates"] = {"spacing": SPACING_50}
    spec50 = SearchSpec.model_validate(doc)
    res50 = run_search(scene, spec50, lp=False)
    top = res50.candidates[:50]
    ids = [f"S{k + 1:02d}" for k in range(len(top))]
    cold_c, constants_s, constants_w, built = best_of(
        lambda: build_candidates(res50.building, top, ids), repeats=2
    )
    cf, failures, agreement, _ = built
    worst = max(a["lam0_rel"] for a in agreement.values())
    library = OverturningLibrary.load()
    f_p = log_grid(0.5, 10.0, 400)

    def rank() -> list[str]:
        env, _ = envelope_doc(cf, f_p, library=library)
        scores = {}
        for entry in env.mechanisms:
            vals = [v for v in entry.a_p_min_g if v is not None]
            scores[entry.id] = float(np.exp(np.mean(np.log(vals)))) if vals else math.inf
        return sorted(scores, key=lambda k: scores[k])

    cold_r, rank_s, rank_w, order = best_of(rank)
    motions, record_source = records()
    sub = ConstantsFile(mechanisms=[m for m in cf.mechanisms if m.id in order[:10]])

    def run_records() -> list[Any]:
        with single_threaded():
            return [scales_to_overturn(sub, m) for m in motions]

    cold_rec, records_s, records_w, _ = best_of(run_records, repeats=1)
    # the LP check
    bld = building_from_scene(scene, spec)
    facade = res.candidates[0]
    heights = [c.hinge_z for c in res.candidates if c.facade == facade.facade]
    angles = {
        p.wall.id: [v for k, v in c.params.items() if k.startswith("beta_")]
        for c in res.candidates
        if c.facade == facade.facade
        for p in c.pieces[1:]
    }

    def lp_at(extra: list[float]) -> tuple[Any, Any]:
        model = facade_lp_model(
            bld, facade.facade, "outward", heights + extra, angles, loads=facade.contacts
        )
        return model, solve_lp(model)

    cold_lp, lp_s, lp_w, (m_nat, r_nat) = best_of(lambda: lp_at([]))
    dense = _near_300(bld, facade.facade, heights, angles, facade.contacts)
    cold_lp3, lp3_s, lp3_w, (m300, r300) = best_of(lambda: lp_at(dense))
    strip = _strip_model()
    cold_st, strip_s, strip_w, (m_st, r_st) = best_of(lambda: (strip, solve_lp(strip)))
    pal = palazzo_stages()
    total = time.perf_counter() - t_all
    spacing = dense[1] - dense[0] if len(dense) > 1 else float("nan")
    rows = [
        ("read the .3dm (rhino3dm; meshes made on first use)", cold_read, read_s, read_w, None),
        (
            f"search: building + {n_cands} candidates ({evaluations} evaluations of λ0)",
            cold_search, search_s, search_w, "search",
        ),
        (
            f"constants of the top {len(top)} (builder, {len(failures)} failures)",
            cold_c, constants_s, constants_w, "constants",
        ),
        (
            "pulse ranking of the 50 over 400 frequencies (library)",
            cold_r, rank_s, rank_w, "ranking",
        ),
        (
            f"20 records x the 10 best ranked ({record_source})",
            cold_rec, records_s, records_w, "records",
        ),
        (
            f"LP check of the façade ({len(m_nat.blocks)} blocks, {r_nat.n_rows} rows)",
            cold_lp, lp_s, lp_w, "lp",
        ),
        (
            f"LP check, a line every {spacing:.3g} m ({len(m300.blocks)} blocks, "
            f"{r300.n_rows} rows)",
            cold_lp3, lp3_s, lp3_w, "lp",
        ),
        (
            f"LP check, two-block strip ({len(m_st.blocks)} blocks, {r_st.n_rows} rows)",
            cold_st, strip_s, strip_w, "lp",
        ),
        ("palazzo: read the .3dm", *pal["read"], None),
        (
            f"palazzo: search, building + {pal['n_candidates']} candidates "
            f"({pal['evaluations']} evaluations of λ0)",
            *pal["search"], "palazzo",
        ),
        (
            f"palazzo: the whole `rockmech search` ({pal['n_built']} built, figure; "
            "CPU of the child)",
            *pal["cli"], "palazzo_cli",
        ),
    ]  # fmt: skip
    md = report(info, rows, total, len(res50.candidates), worst, spacing, n_cands, times={
        "search": search_s, "read": read_s, "constants": constants_s, "rank": rank_s,
    }, palazzo=pal)  # fmt: skip
    print(md)
    if not args.no_docs:
        write_section(DOC_MD, "search_speed", md)
        print(f"wrote the search_speed section of {DOC_MD}")
    return 0


def report(
    info: dict[str, str],
    rows: list[tuple[str, float, float, float, Any]],
    total: float,
    n50: int,
    worst: float,
    spacing: float,
    n_cands: int,
    times: dict[str, float],
    palazzo: dict[str, Any],
) -> str:
    """Write the ``search_speed`` section of ``docs/benchmarks.md`` (markdown)."""
    lines = [
        "| stage | cold (CPU) | best warm (CPU) | best warm (wall) | limit | ratio |",
        "|---|---|---|---|---|---|",
    ]
    targets = ["| target | result | measured / limit |", "|---|---|---|"]
    for label, cold, best, wall, key in rows:
        limit = LIMITS.get(key) if key else None
        measured = wall if key in WALL_LIMITED else best
        clock = "wall" if key in WALL_LIMITED else "CPU"
        ratio = "-" if limit is None else f"{measured / limit:.2f} ({clock})"
        lines.append(
            f"| {label} | {fmt_time(cold)} | {fmt_time(best)} | {fmt_time(wall)} | "
            f"{'-' if limit is None else fmt_time(limit)} | {ratio} |"
        )
        if limit is not None:
            targets.append(
                f"| {label} <= {fmt_time(limit)} ({clock}) | "
                f"{'PASS' if measured <= limit else 'FAIL'} | "
                f"{fmt_time(measured)} / {fmt_time(limit)} = {measured / limit:.2f} |"
            )
    tm = palazzo["timings"]
    staged = tm["read_s"] + tm["search_s"] + tm["lp_s"] + tm["constants_and_ranking_s"]
    cli_wall = palazzo["cli"][2]
    out = [
        "## Mechanism search speed (`benchmarks/search_speed.py`)",
        "",
        "Latest figures of `benchmarks/search_speed.py`. Re-run with "
        "`.venv/bin/python benchmarks/search_speed.py`; it rewrites this section only.",
        "",
        "### Machine and run",
        "",
        f"- Date: {info['date']}; rockmech commit: {info['commit']}",
        f"- CPU: {info['cpu']}; nproc = {info['nproc']}, threads pinned to 1; load average "
        f"(1, 5, 15 min): {info['load']} (the machine is shared)",
        f"- Python {info['python']}, numpy {info['numpy']}, scipy {info['scipy']}, numba "
        f"{info['numba']}, shapely {info['shapely']}, manifold3d {info['manifold3d']}",
        f"- Command: `.venv/bin/python benchmarks/search_speed.py`; whole run {total / 60:.1f} min",
        "",
        "### Method",
        "",
        "The example `search_facade.3dm` (3-storey façade, 6 windows, 2 return walls, back "
        "wall, 2 floors, roof, a tie-bar) with `search_facade.search.json` (all families, both "
        f"directions). One cold call, then the best of {REPEATS} warm calls (the builder "
        "twice, the records once), in one process on one thread. The 50 mechanisms come from "
        f"the same spec with a hinge line every {SPACING_50:g} m ({n50} candidates); the "
        f"builder's λ0 agrees with the search's to {worst:.1e} at worst. The ~300-block "
        f"check adds a line every {spacing:.3g} m to the façade's own. Times are the "
        "process's CPU time on one thread, the targets' measure of work on one core; the "
        "wall-clock time is given beside it (on this shared machine it also counts the time "
        "other processes held the core).",
        "",
        f"The palazzo (issue #37) is written by `palazzo` and `palazzo_spec` of "
        f"`examples/scenes/build_scenes.py`: {palazzo['n_walls']} walls (an outer ring, a "
        f"courtyard ring and cross walls between them), 4 storeys of 3.5 m, "
        f"{palazzo['n_openings']} windows, {palazzo['n_levels']} levels (a floor in every "
        "room at each storey, and the roof), good and poor junctions; the spec asks for "
        "every family in both directions and the global check (the command's defaults). Its "
        "search is timed as the façade's; the whole command `rockmech search <scene> "
        "<spec> --out <dir>` runs in a subprocess (threads pinned to 1 as here; "
        "`PYTHONDONTWRITEBYTECODE` unset, so that it reads the bytecode caches an installed "
        "rockmech has, as the start-up benchmark does) "
        f"{CLI_RUNS} times, the first reported as the cold run (its wall clock "
        f"{fmt_time(palazzo['cli_cold_wall'])}"
        "), the best wall clock of the others against the limit; the CPU columns are the "
        "child's.",
        "",
        "### Results",
        "",
        *lines,
        "",
        "### Targets",
        "",
        *targets,
        "",
        "### Reading",
        "",
        f"The search (the building read as prisms, {n_cands} candidates refined on the exact "
        f"λ0) takes {fmt_time(times['search'])} of CPU on one core, reading the building's "
        "solids from the model included. The builder computes the constants of 50 "
        f"mechanisms, cutting real meshes with manifold3d, in {fmt_time(times['constants'])}, "
        f"and the library ranks them over 400 frequencies in {fmt_time(times['rank'])}. For "
        "comparison, the published Rhino tool (Funari, Mehrotra and Lourenço 2021) reports "
        "under 5 s for its limit-analysis search and up to 10 s per rocking solution; here a "
        "rocking solution of El Centro takes about 100 µs.",
        "",
        f"The palazzo's search ({palazzo['n_candidates']} candidates on its "
        f"{palazzo['n_walls']} walls) takes {fmt_time(palazzo['search'][1])} of CPU. Its "
        f"whole command takes {fmt_time(cli_wall)} of wall clock; by the command's own "
        f"timings (`search.json`, wall clock) reading the building from the scene's "
        f"objects (`read_s`: the plan, the walls as prisms, the junctions and the levels' "
        f"contacts, the first search in the process; the `.3dm` file's own reading, timed "
        f"above, comes before it) takes {fmt_time(tm['read_s'])}, the search "
        f"{fmt_time(tm['search_s'])}, the global check "
        f"({palazzo['lp_blocks']} macro-blocks over every façade and direction) "
        f"{fmt_time(tm['lp_s'])}, the builder and the ranking of the {palazzo['n_built']} "
        f"kept {fmt_time(tm['constants_and_ranking_s'])}, and the rest (the interpreter's "
        "start-up and imports, writing the files and drawing the figure) "
        f"{fmt_time(max(cli_wall - staged, 0.0))}.",
    ]
    return "\n".join(out)


#: The example scenes' builder module, loaded on call (``_docs.build_scenes``).
_build_scenes = build_scenes


def _rockmech() -> str:
    """Return the ``rockmech`` command of this interpreter's environment."""
    exe = shutil.which("rockmech", path=str(Path(sys.executable).parent))
    if exe is None:
        raise SystemExit(
            f"no `rockmech` command beside {sys.executable}: install the project (make install)"
        )
    return exe


def _children_cpu() -> float:
    """CPU time (user + system) of the finished child processes so far [s]."""
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def palazzo_stages() -> dict[str, Any]:
    """Time the palazzo's read, search and whole command (the module's docstring, 6)."""
    build = _build_scenes()
    exe = _rockmech()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        scene_path = build.palazzo(folder)
        spec_path = folder / "palazzo.search.json"
        spec_path.write_text(json.dumps(build.palazzo_spec(), indent=1))
        spec = parse_search_spec(spec_path.read_bytes(), spec_path.name)
        cold_read, read_s, read_w, scene = best_of(lambda: read_scene(scene_path))
        cold_s, search_s, search_w, res = best_of(lambda: run_search(scene, spec, lp=False))
        runs = []
        for k in range(CLI_RUNS):
            out = folder / f"out_{k}"
            cpu, wall = _children_cpu(), time.perf_counter()
            proc = subprocess.run(
                [exe, "search", str(scene_path), str(spec_path), "--out", str(out)],
                capture_output=True,
                text=True,
                env=command_env(),  # with bytecode caches, as an installed rockmech runs
            )
            wall, cpu = time.perf_counter() - wall, _children_cpu() - cpu
            if proc.returncode != 0:
                raise SystemExit(f"`rockmech search` on the palazzo failed:\n{proc.stderr}")
            doc = json.loads((out / "search.json").read_text())
            runs.append((wall, cpu, doc))
    best_wall, _, best_doc = min(runs[1:] or runs, key=lambda r: r[0])
    return {
        "read": (cold_read, read_s, read_w),
        "search": (cold_s, search_s, search_w),
        "cli": (runs[0][1], min(r[1] for r in runs[1:] or runs), best_wall),
        "cli_cold_wall": runs[0][0],
        "n_candidates": len(res.candidates),
        "evaluations": sum(c.n_evaluations for c in res.candidates),
        "n_walls": len(res.building.walls),
        "n_openings": sum(len(w) for w in build.palazzo_windows().values()),
        "n_levels": len(spec.levels),
        "n_built": best_doc["counts"]["built"],
        "lp_blocks": best_doc["counts"]["lp_blocks"],
        "timings": best_doc["timings"],
    }


def _near_300(bld: Any, facade: str, heights: list[float], angles: Any, loads: Any) -> list[float]:
    """Extra lines (a regular spacing) giving the façade's check closest to 300 blocks."""
    best: list[float] = []
    best_n = 0
    for spacing in LP_SPACINGS:
        extra = [float(z) for z in np.arange(spacing, 10.5, spacing)]
        model = facade_lp_model(bld, facade, "outward", heights + extra, angles, loads=loads)
        if best_n < len(model.blocks) <= 300:
            best, best_n = extra, len(model.blocks)
    return best


def _strip_model() -> Any:
    """Build the two-block strip of docs/search.md V1 cut into 300 blocks (b 0.3, h 3, N = W)."""
    import tempfile

    sys.path.insert(0, str(REPO / "tests" / "search"))
    from search_scenes import two_block_wall

    from shared_schema.rules import G

    w = 1800.0 * G * 0.3 * 3.0
    with tempfile.TemporaryDirectory() as tmp:
        scene = read_scene(two_block_wall(Path(tmp)))
    spec = SearchSpec.model_validate(
        {
            "walls": [{"id": "W", "object": "wall", "density": 1800.0, "overburden": {"force": w}}],
            "levels": [
                {"id": "S", "kind": "floor", "objects": ["slab"], "density": 2400.0, "tied": True}
            ],
        }
    )
    bld = building_from_scene(scene, spec)
    heights = [3.0 * k / 300 for k in range(1, 300)]
    return facade_lp_model(bld, "W", "outward", heights, overburden=(w, 0.0))


if __name__ == "__main__":
    sys.exit(main())
