"""Speed and peak memory of the geometry pipeline: scene + spec -> kinematic constants.

What is measured
----------------
Two scan-like walls, each a closed structured triangle mesh with a smooth relief on its two
large faces (``examples/scenes/build_scenes.py``), with the spec
``examples/specs/scan_wall.spec.json`` (two-sided rocking about two line objects):

1. The 200k example: ``examples/scenes/scan_wall.3dm`` (201,800 triangles).
2. A large wall of about 1,000,000 triangles (``LARGE_CELLS``; ``QUICK_LARGE_CELLS`` in a
   quick run), built in memory with ``build_scenes.grid_box_solid`` and ``build_scenes._relief``
   (the construction of the example, on a finer grid), and also written to a temporary
   ``.3dm`` file with rhino3dm (same object names, so the same spec applies).

Each wall goes through two paths:

- *in memory*: ``constants_from_spec(parse_spec(text), scene, ...)`` where ``scene`` is a
  :class:`~cad_maths.scene_3dm.Scene` whose ``mesh`` and ``line`` return the in-memory
  mesh (a fresh ``TriMesh`` per call, so no validity cache carries over between repeats) and
  the axis end points; ``find`` is the real one. This runs the real code path: validation,
  mass properties, two rocking sides, restitution, constants-file validation.
- *from the file*: ``Scene.from_3dm(path)``, then ``parse_spec`` and ``constants_from_spec``
  on the loaded scene, as ``rockmech constants`` does. ``Scene.mesh`` (called inside
  ``constants_from_spec``) copies the faces out of rhino3dm one at a time.

How
---
Every case runs in a fresh subprocess: one cold call (lazy imports: scipy etc.), then
``REPEATS`` warm calls (best of), then one more call under ``tracemalloc``. Stage times come
from timers wrapped around a few functions (``Scene.from_3dm``, ``scene_3dm._mesh_arrays``,
``Scene.mesh``, ``check_solid``, ``mass_properties``, ``rocking_side``); each stage's time is
exclusive of the stages it calls. Peak memory is the subprocess's ``ru_maxrss`` (and
``VmHWM``) after the warm calls, and the tracemalloc peak (Python objects and numpy buffers;
rhino3dm's C++ allocations are not traced) of the extra call, above what was traced before it.

Targets: constants of the 1M wall <= 2 s and of the 200k example <= 0.5 s, judged on the
in-memory path (the part rockmech controls) and also reported including ``.3dm`` reading;
peak memory <= 1.5 GB judged on the 1M wall read from its file (end to end).

Run ``.venv/bin/python benchmarks/geometry_speed.py`` for the full run (about 2 minutes),
which rewrites the ``geometry_speed`` section of ``docs/benchmarks.md``; ``--quick`` is a
smoke run (one repeat, a 300k wall) that writes no docs unless ``--write-docs``.
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, Callable, Optional, Union

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

# The parent imports nothing heavy: a subprocess's ru_maxrss starts from its parent's peak
# RSS on Linux (vfork + exec), so a heavy parent would inflate every worker's figure.
from _docs import (  # noqa: E402  (benchmarks/ is not a package)
    DOC_MD,
    build_scenes,
    fmt_time,
    load_average,
    machine_info,
    md_table,
    text_table,
    write_section,
)

#: The 200k example and its spec.
EXAMPLE_3DM = REPO / "examples" / "scenes" / "scan_wall.3dm"
SPEC_JSON = REPO / "examples" / "specs" / "scan_wall.spec.json"
#: The script that builds the example scenes (its mesh construction is reused).
#: Grid cells (thickness, length, height) of the large wall: 1,007,552 triangles.
LARGE_CELLS = (1, 448, 560)
#: Grid cells of the large wall in a quick run: 302,084 triangles.
QUICK_LARGE_CELLS = (1, 245, 306)
#: Warm repeats per case (best of), full and quick run.
REPEATS = 3
QUICK_REPEATS = 1
#: Targets from the issue [s], [MB = 1e6 bytes].
TARGET_LARGE_S = 2.0
TARGET_EXAMPLE_S = 0.5
TARGET_PEAK_MB = 1500.0
#: Modules whose first import a cold call may pay for.
HEAVY = ("rhino3dm", "scipy", "manifold3d", "shapely", "trimesh", "pydantic")
#: Import-time probes, in order; each time is what that import adds to the ones before.
IMPORTS = (
    ("numpy", "numpy"),
    ("rockmech: scene_3dm, mechanisms.build, shared_schema.spec (with pydantic)", None),
    ("rhino3dm", "rhino3dm"),
    ("scipy.sparse.csgraph", "scipy.sparse.csgraph"),
    ("manifold3d", "manifold3d"),
    ("shapely", "shapely"),
)
#: Stage rows: key, label.
STAGES = (
    ("read", "read .3dm (File3dm.Read, object list)"),
    ("extract", "copy mesh out of rhino3dm (_mesh_arrays)"),
    ("mesh", "weld + orient (rest of Scene.mesh)"),
    ("check_solid", "check_solid (full check + cached re-check)"),
    ("mass_properties", "mass_properties (integrals)"),
    ("rocking_side", "rocking_side (R, alpha, I_O of each side)"),
    ("other", "other (spec, axes, eta, constants-file validation)"),
)
COMMAND = ".venv/bin/python benchmarks/geometry_speed.py"
MB = 1e6


# ------------------------------------------------------------------------------------------
# Worker side (runs in a fresh subprocess)
# ------------------------------------------------------------------------------------------


#: The example scenes' builder module, loaded on call (``_docs.build_scenes``).
_build_scenes = build_scenes


def scan_wall_mesh(bs: Any, cells: tuple[int, int, int]) -> tuple[Any, Any]:
    """Vertices and faces of the scan wall on a grid of ``cells`` (build_scenes' recipe)."""
    t = bs.SCAN_SIZE[0]

    def displace(p: Any) -> Any:
        q = p.copy()
        s = p[:, 0] / t  # 0 on the outer face (x = 0), 1 on the inner face
        q[:, 0] += (1.0 - s) * bs._relief(p[:, 1], p[:, 2], 0.0) + s * bs._relief(
            p[:, 1], p[:, 2], 1.7
        )
        return q

    return bs.grid_box_solid(bs.SCAN_SIZE, cells, displace)


def axis_lines(bs: Any) -> dict[str, tuple[tuple[float, float, float], ...]]:
    """End points [m] of the two axes of the scan wall (as in build_scenes.scan_wall)."""
    t, length = bs.SCAN_SIZE[0], bs.SCAN_SIZE[1]
    return {
        "axis": ((t, 0.0, 0.0), (t, length, 0.0)),
        "axis_back": ((0.0, 0.0, 0.0), (0.0, length, 0.0)),
    }


def prepare(data: Path, large_cells: tuple[int, int, int]) -> dict[str, Any]:
    """Build both walls in memory (saved as .npy) and write the large one to a .3dm file."""
    import numpy as np

    bs = _build_scenes()
    out: dict[str, Any] = {}
    for size, cells in (("example", bs.SCAN_CELLS), ("large", large_cells)):
        t0 = time.perf_counter()
        v, f = scan_wall_mesh(bs, cells)
        out[f"{size}_build_s"] = time.perf_counter() - t0
        np.save(data / f"{size}_v.npy", v)
        np.save(data / f"{size}_f.npy", f)
        out[f"{size}_triangles"] = int(f.shape[0])
        out[f"{size}_vertices"] = int(v.shape[0])
        out[f"{size}_cells"] = list(cells)
    # the large wall as a .3dm, through build_scenes.Builder (units, tolerance, ids, layers)
    t0 = time.perf_counter()
    v = np.load(data / "large_v.npy")
    f = np.load(data / "large_f.npy")
    b = bs.Builder("scan_wall_large")
    m = b.r3.Mesh()
    add_v, add_f = m.Vertices.AddPoint3d, m.Faces.AddFace
    for x, y, z in v.tolist():
        add_v(x, y, z)
    for i, j, k in f.tolist():
        add_f(i, j, k)
    b.model.Objects.AddMesh(m, b.attrs("scan_wall", "Scan", "stone"))
    for name, (a, c) in axis_lines(bs).items():
        b.line(name, "Axes", a, c)
    path = b.write(data / "large.3dm")
    out["large_write_s"] = time.perf_counter() - t0
    out["large_file_mb"] = path.stat().st_size / MB
    out["example_file_mb"] = EXAMPLE_3DM.stat().st_size / MB
    return out


def import_times() -> list[tuple[str, float]]:
    """Time each import of ``IMPORTS`` in order, in this (fresh) process."""
    import importlib

    rows = []
    for label, mod in IMPORTS:
        t0 = time.perf_counter()
        if mod is None:
            importlib.import_module("cad_maths.scene_3dm")
            importlib.import_module("cad_maths.mechanisms.build")
            importlib.import_module("shared_schema.spec")
        else:
            importlib.import_module(mod)
        rows.append((label, time.perf_counter() - t0))
    return rows


class StageTimer:
    """Exclusive wall time per stage of wrapped functions (nested stages subtracted)."""

    def __init__(self) -> None:
        self.times: dict[str, float] = {}
        self.calls: dict[str, int] = {}
        self._stack: list[list[float]] = []  # per open stage: time spent in child stages

    def reset(self) -> None:
        """Forget the times and calls recorded so far."""
        self.times.clear()
        self.calls.clear()

    def wrap(self, key: str, fn: Callable[..., Any]) -> Callable[..., Any]:
        """Return ``fn`` timed as stage ``key``."""

        def timed(*args: Any, **kwargs: Any) -> Any:
            self._stack.append([0.0])
            t0 = time.perf_counter()
            try:
                return fn(*args, **kwargs)
            finally:
                dt = time.perf_counter() - t0
                child = self._stack.pop()[0]
                self.times[key] = self.times.get(key, 0.0) + dt - child
                self.calls[key] = self.calls.get(key, 0) + 1
                if self._stack:
                    self._stack[-1][0] += dt

        return timed


def install_timers(timer: StageTimer) -> None:
    """Wrap the pipeline's stages (module attributes looked up at call time)."""
    import cad_maths.geometry.massprops as massprops
    import cad_maths.geometry.validate as validate
    import cad_maths.mechanisms.single as single
    import cad_maths.scene_3dm as scene_3dm

    scene_3dm._mesh_arrays = timer.wrap("extract", scene_3dm._mesh_arrays)
    scene_3dm.Scene.mesh = timer.wrap("mesh", scene_3dm.Scene.mesh)  # type: ignore[method-assign]
    validate.check_solid = timer.wrap("check_solid", validate.check_solid)
    massprops.mass_properties = timer.wrap("mass_properties", massprops.mass_properties)
    single.rocking_side = timer.wrap("rocking_side", single.rocking_side)


def memory_scene(data: Path, size: str) -> Any:
    """Return a Scene whose solid and axes come from memory (``find`` is the real one)."""
    import numpy as np

    from cad_maths.geometry.mesh import TriMesh
    from cad_maths.scene_3dm import Scene, SceneObject

    bs = _build_scenes()
    v = np.load(data / f"{size}_v.npy")
    f = np.load(data / f"{size}_f.npy")
    lines = {k: (np.array(a, float), np.array(b, float)) for k, (a, b) in axis_lines(bs).items()}

    class MemoryScene(Scene):
        def mesh(self, obj: Any, require_closed: bool = True) -> Any:
            # a new TriMesh each call, as Scene.mesh makes: check_solid's cache never hits
            return TriMesh(v, f, obj.name, {"id": obj.id, "layer": obj.layer, "kind": obj.kind})

        def line(self, obj: Any) -> Any:
            a, b = lines[obj.name]
            return a.copy(), b.copy()

    objects = [SceneObject("00000000-0000-0000-0000-000000000001", "scan_wall", "Scan", "mesh")]
    objects += [
        SceneObject(f"00000000-0000-0000-0000-00000000000{k + 2}", name, "Axes", "line")
        for k, name in enumerate(lines)
    ]
    return MemoryScene(objects, path=f"<memory: {size} wall>")


def _rss_mb() -> tuple[float, float, float]:
    """Return ru_maxrss, VmHWM and VmRSS of this process [MB]."""
    maxrss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024 / MB
    hwm = rss = float("nan")
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmHWM:"):
                hwm = float(line.split()[1]) * 1024 / MB
            elif line.startswith("VmRSS:"):
                rss = float(line.split()[1]) * 1024 / MB
    except OSError:
        pass
    return maxrss, hwm, rss


def summary(cf: Any) -> dict[str, float]:
    """Return a few numbers of the result, to compare the paths."""
    m = cf.mechanisms[0]
    geo = m.geometry or {}
    return {
        "mass_kg": float(geo["mass_kg"]),
        "p_eq": float(m.positive.p_eq),
        "lam": float(m.positive.lam),
        "I0": float(m.positive.I0),
        "eta": float(m.eta),
    }


def run_case(kind: str, size: str, data: Path, repeats: int) -> dict[str, Any]:
    """One case in this fresh process: cold call, warm repeats, tracemalloc call."""
    before = set(sys.modules)
    t0 = time.perf_counter()
    from cad_maths.mechanisms.build import constants_from_spec
    from cad_maths.scene_3dm import Scene
    from shared_schema.spec import parse_spec

    import_s = time.perf_counter() - t0
    timer = StageTimer()
    install_timers(timer)
    text = SPEC_JSON.read_bytes()
    path = EXAMPLE_3DM if size == "example" else data / "large.3dm"
    mem_scene = memory_scene(data, size) if kind == "memory" else None

    def call() -> dict[str, Any]:
        timer.reset()
        t0 = time.perf_counter()
        if mem_scene is None:
            t_read = time.perf_counter()
            scene = Scene.from_3dm(path)
            timer.times["read"] = time.perf_counter() - t_read
        else:
            scene = mem_scene
        t1 = time.perf_counter()
        cf = constants_from_spec(
            parse_spec(text, SPEC_JSON.name),
            scene,
            scene_name=path.name,
            spec_name=SPEC_JSON.name,
        )
        t2 = time.perf_counter()
        stages = {k: timer.times.get(k, 0.0) for k, _ in STAGES if k != "other"}
        stages["other"] = (t2 - t0) - sum(stages.values())
        return {
            "total_s": t2 - t0,
            "constants_s": t2 - t1,
            "stages": stages,
            "calls": dict(timer.calls),
            "result": summary(cf),
        }

    rss_start = _rss_mb()
    cold = call()
    lazy = sorted({m.split(".")[0] for m in set(sys.modules) - before} & set(HEAVY))
    warm = [call() for _ in range(repeats)]
    rss = _rss_mb()

    import tracemalloc

    tracemalloc.start()
    base = tracemalloc.get_traced_memory()[0]
    tracemalloc.reset_peak()
    call()
    peak = tracemalloc.get_traced_memory()[1] - base
    tracemalloc.stop()
    best = min(warm, key=lambda r: r["total_s"])
    return {
        "kind": kind,
        "size": size,
        "import_s": import_s,
        "cold": cold,
        "lazy_imports": lazy,
        "best": best,
        "totals": [r["total_s"] for r in warm],
        "constants": [r["constants_s"] for r in warm],
        "best_constants_s": min(r["constants_s"] for r in warm),
        "rss_start_mb": rss_start[0],
        "maxrss_mb": rss[0],
        "hwm_mb": rss[1],
        "tracemalloc_peak_mb": peak / MB,
    }


def worker(argv: list[str]) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--worker", required=True, choices=["prepare", "imports", "file", "memory"])
    ap.add_argument("--data", type=Path, required=True)
    ap.add_argument("--size", default="example", choices=["example", "large"])
    ap.add_argument("--repeats", type=int, default=REPEATS)
    ap.add_argument("--cells", default=",".join(map(str, LARGE_CELLS)))
    a = ap.parse_args(argv)
    if a.worker == "prepare":
        cells = tuple(int(c) for c in a.cells.split(","))
        out: Any = prepare(a.data, (cells[0], cells[1], cells[2]))
    elif a.worker == "imports":
        out = import_times()
    else:
        out = run_case(a.worker, a.size, a.data, a.repeats)
    print(json.dumps(out))
    return 0


# ------------------------------------------------------------------------------------------
# Parent side
# ------------------------------------------------------------------------------------------


def spawn(*args: str) -> Any:
    """Run this script as a worker in a fresh interpreter; return its JSON answer."""
    cmd = [sys.executable, str(Path(__file__).resolve()), *args]
    proc = subprocess.run(cmd, capture_output=True, text=True, cwd=REPO, check=False)
    if proc.returncode != 0:
        sys.stderr.write(proc.stdout + proc.stderr)
        raise RuntimeError(f"worker {' '.join(args)} failed (exit {proc.returncode})")
    return json.loads(proc.stdout.strip().splitlines()[-1])


def verdict(ok: Union[bool, str, None]) -> str:
    if ok == "info":
        return "INFO"
    return "SKIP" if ok is None else ("PASS" if ok else "FAIL")


def fmt_times(times: list[float]) -> str:
    return ", ".join(fmt_time(t) for t in times)


def fmt_mb(x: float) -> str:
    return f"{x:,.0f} MB"


def tri(n: int) -> str:
    return f"{n:,}"


def case_rows(prep: dict[str, Any], res: dict[str, dict[str, Any]]) -> list[list[str]]:
    """One row per (wall, path): best total, breakdown summary, cold call, memory."""
    rows = []
    for size in ("example", "large"):
        for kind in ("memory", "file"):
            r = res[f"{kind}_{size}"]
            b = r["best"]
            wall = f"{tri(prep[f'{size}_triangles'])} triangles"
            if kind == "memory":
                what = "constants from the in-memory mesh"
                constants = fmt_time(r["best_constants_s"])
                read_mesh = "-"
            else:
                what = "end to end from .3dm (read + constants)"
                constants = fmt_time(r["best_constants_s"])
                st = b["stages"]
                read_mesh = fmt_time(st["read"] + st["extract"] + st["mesh"])
            rows.append(
                [
                    wall,
                    what,
                    read_mesh,
                    constants,
                    fmt_time(b["total_s"]),
                    fmt_times(r["totals"]),
                    fmt_time(r["cold"]["total_s"]),
                    fmt_mb(r["maxrss_mb"]),
                    fmt_mb(r["tracemalloc_peak_mb"]),
                ]
            )
    return rows


HEAD_CASES = [
    "wall",
    "path",
    "(a) read + mesh",
    "(b) constants",
    "(c) total (best)",
    "all repeats (total)",
    "cold first call",
    "peak RSS",
    "tracemalloc peak",
]


def stage_rows(res: dict[str, dict[str, Any]]) -> tuple[list[str], list[list[str]]]:
    """Exclusive stage times of the best run of each case."""
    keys = [("memory", "example"), ("file", "example"), ("memory", "large"), ("file", "large")]
    head = ["stage"] + [
        f"{'200k' if s == 'example' else 'large'} {'memory' if k == 'memory' else '.3dm'}"
        for k, s in keys
    ]
    rows = []
    for key, label in STAGES:
        row = [label]
        for k, s in keys:
            b = res[f"{k}_{s}"]["best"]
            t = b["stages"][key]
            n = b["calls"].get(key)
            row.append("-" if (t == 0.0 and key in ("read", "extract", "mesh")) else fmt_time(t))
            if n and key in ("check_solid", "rocking_side") and n > 1:
                row[-1] += f" ({n} calls)"
        rows.append(row)
    rows.append(["total"] + [fmt_time(res[f"{k}_{s}"]["best"]["total_s"]) for k, s in keys])
    return head, rows


def memory_rows(res: dict[str, dict[str, Any]], prep: dict[str, Any]) -> list[list[str]]:
    rows = []
    for size in ("example", "large"):
        for kind in ("memory", "file"):
            r = res[f"{kind}_{size}"]
            rows.append(
                [
                    f"{tri(prep[f'{size}_triangles'])} triangles",
                    "in memory" if kind == "memory" else "from .3dm",
                    fmt_mb(r["rss_start_mb"]),
                    fmt_mb(r["maxrss_mb"]),
                    fmt_mb(r["hwm_mb"]),
                    fmt_mb(r["tracemalloc_peak_mb"]),
                ]
            )
    return rows


HEAD_MEMORY = [
    "wall",
    "path",
    "RSS after imports",
    "peak RSS (ru_maxrss)",
    "VmHWM",
    "tracemalloc peak of one call",
]


def overhead_rows(res: dict[str, dict[str, Any]], imports: list[list[Any]]) -> list[list[str]]:
    rows = [[f"import {label}", fmt_time(t)] for label, t in imports]
    for size in ("example", "large"):
        for kind in ("memory", "file"):
            r = res[f"{kind}_{size}"]
            extra = r["cold"]["total_s"] - r["best"]["total_s"]
            lazy = ", ".join(r["lazy_imports"]) or "none"
            rows.append(
                [
                    f"first call, {'200k' if size == 'example' else 'large'} "
                    f"{'in memory' if kind == 'memory' else 'from .3dm'}: extra over best",
                    f"{fmt_time(extra)} (lazy imports: {lazy})",
                ]
            )
    return rows


def agreement_rows(res: dict[str, dict[str, Any]]) -> list[list[str]]:
    """Relative differences between the in-memory and the file path (same geometry)."""
    rows = []
    for size in ("example", "large"):
        a = res[f"memory_{size}"]["best"]["result"]
        b = res[f"file_{size}"]["best"]["result"]
        diff = max(abs(a[k] - b[k]) / max(abs(a[k]), abs(b[k]), 1e-300) for k in a)
        rows.append(
            [
                "200k" if size == "example" else "large",
                f"{b['mass_kg']:.6g} kg",
                f"{b['p_eq']:.6g} rad/s",
                f"{b['lam']:.6g}",
                f"{b['eta']:.6g}",
                f"{diff:.1e}",
            ]
        )
    return rows


HEAD_AGREE = ["wall", "mass", "p_eq (+)", "lam (+)", "eta", "max rel. diff memory vs .3dm"]


def own_code_s(r: dict[str, Any]) -> float:
    """Time of a .3dm call spent in rockmech's code: all but rhino3dm reading and copying."""
    st = r["best"]["stages"]
    return float(r["best"]["total_s"] - st["read"] - st["extract"])


#: A target line: name, verdict (True/False, None = not measured, "info" = not a target),
#: measured value.
Target = tuple[str, Union[bool, str, None], str]


def targets(prep: dict[str, Any], res: dict[str, dict[str, Any]]) -> list[Target]:
    n_large = prep["large_triangles"]
    big = n_large >= 1_000_000
    lm, lf = res["memory_large"], res["file_large"]
    em, ef = res["memory_example"], res["file_example"]
    out: list[Target] = []

    def large(name: str, ok: Union[bool, str], val: str) -> None:
        if big:
            out.append((name, ok, val))
        else:
            out.append((name, None, f"not measured (quick run: {tri(n_large)} triangles): {val}"))

    large(
        f"constants of a 1,000,000-triangle wall <= {TARGET_LARGE_S:g} s, judged on "
        "constants_from_spec with the in-memory mesh (validation, mass properties, two "
        "sides, restitution)",
        lm["best_constants_s"] <= TARGET_LARGE_S,
        fmt_time(lm["best_constants_s"]),
    )
    large(
        f"  same, including .3dm reading (rhino3dm): Scene.from_3dm + constants_from_spec "
        f"<= {TARGET_LARGE_S:g} s",
        lf["best"]["total_s"] <= TARGET_LARGE_S,
        fmt_time(lf["best"]["total_s"]),
    )
    large(
        "  (info) of that, rockmech's own code: all but rhino3dm reading the file and "
        "handing the mesh over (i.e. weld + orient + constants)",
        "info",
        fmt_time(own_code_s(lf)),
    )
    large(
        f"peak memory <= {TARGET_PEAK_MB / 1000:g} GB, judged on the 1,000,000-triangle wall "
        "end to end from .3dm (peak RSS of its subprocess)",
        max(lf["maxrss_mb"], lf["hwm_mb"]) <= TARGET_PEAK_MB,
        fmt_mb(lf["maxrss_mb"]),
    )
    out.append(
        (
            f"the 200k-triangle example <= {TARGET_EXAMPLE_S:g} s, judged on "
            "constants_from_spec with the in-memory mesh",
            em["best_constants_s"] <= TARGET_EXAMPLE_S,
            fmt_time(em["best_constants_s"]),
        )
    )
    out.append(
        (
            "  same, constants_from_spec on the scene Scene.from_3dm loaded (Scene.mesh "
            f"copies the mesh out of rhino3dm inside it) <= {TARGET_EXAMPLE_S:g} s",
            ef["best_constants_s"] <= TARGET_EXAMPLE_S,
            fmt_time(ef["best_constants_s"]),
        )
    )
    out.append(
        (
            "  same, including .3dm reading (rhino3dm): Scene.from_3dm + constants_from_spec "
            f"<= {TARGET_EXAMPLE_S:g} s",
            ef["best"]["total_s"] <= TARGET_EXAMPLE_S,
            fmt_time(ef["best"]["total_s"]),
        )
    )
    out.append(
        (
            "  (info) of that, rockmech's own code (weld + orient + constants)",
            "info",
            fmt_time(own_code_s(ef)),
        )
    )
    return out


def reading(prep: dict[str, Any], res: dict[str, dict[str, Any]]) -> str:
    """Return a short, data-driven reading."""
    lm, lf = res["memory_large"], res["file_large"]
    em, ef = res["memory_example"], res["file_example"]
    st = lf["best"]["stages"]
    in_mem_ok = (
        lm["best_constants_s"] <= TARGET_LARGE_S and em["best_constants_s"] <= TARGET_EXAMPLE_S
    )
    e2e_ok = lf["best"]["total_s"] <= TARGET_LARGE_S and ef["best"]["total_s"] <= TARGET_EXAMPLE_S
    share = (st["read"] + st["extract"]) / lf["best"]["total_s"]
    kernels = ("check_solid", "mass_properties", "rocking_side")
    big = max(kernels, key=lambda k: lm["best"]["stages"][k])
    txt = (
        f"From an in-memory mesh, rockmech turns the {tri(prep['large_triangles'])}-triangle "
        f"wall into kinematic constants in {fmt_time(lm['best_constants_s'])} and the "
        f"200k example in {fmt_time(em['best_constants_s'])}"
        + (" (both within target)" if in_mem_ok else "")
        + f"; `{big}` is the largest part. "
        f"Read from a `.3dm` file the same walls take {fmt_time(lf['best']['total_s'])} and "
        f"{fmt_time(ef['best']['total_s'])}"
        + (" (within target)" if e2e_ok else ", over the targets")
        + f": {100 * share:.0f} % of the large wall's time is rhino3dm reading the file and "
        "handing the mesh to Python as one object per vertex and one per face "
        f"({fmt_time(st['extract'])} in `scene_3dm._mesh_arrays` alone), and `Scene.mesh`'s "
        f"weld and orientation of the copied mesh add {fmt_time(st['mesh'])}. "
    )
    if in_mem_ok and not e2e_ok:
        own_l, own_e = own_code_s(lf), own_code_s(ef)
        over = [
            name
            for name, t, lim in (
                ("large wall", own_l, TARGET_LARGE_S),
                ("200k example", own_e, TARGET_EXAMPLE_S),
            )
            if t > lim
        ]
        txt += (
            "Without rhino3dm's part, rockmech's own code on the file path takes "
            f"{fmt_time(own_l)} and {fmt_time(own_e)}"
            + (
                ", within target, so a bulk hand-over of the vertex and face arrays would "
                "close the gap. "
                if not over
                else f", still over target for the {' and the '.join(over)}: besides a bulk "
                "hand-over of the arrays, `Scene.mesh`'s weld and orientation (which sort "
                "vertices and edges that `check_solid` sorts again) would need to get cheaper. "
            )
        )
    mem_ok = max(lf["maxrss_mb"], lf["hwm_mb"]) <= TARGET_PEAK_MB
    txt += (
        f"Peak memory of the large wall end to end is {fmt_mb(lf['maxrss_mb'])} (of which "
        f"{fmt_mb(lf['rss_start_mb'])} is the interpreter and imports), "
        + (
            f"under {TARGET_PEAK_MB / 1000:g} GB"
            if mem_ok
            else f"over {TARGET_PEAK_MB / 1000:g} GB"
        )
        + "; the Python objects made while copying the mesh out of rhino3dm dominate the "
        f"traced peak ({fmt_mb(lf['tracemalloc_peak_mb'])} against "
        f"{fmt_mb(lm['tracemalloc_peak_mb'])} on the in-memory path). Times depend on the "
        "machine's load (given above)."
    )
    return txt


def write_docs(
    info: dict[str, str],
    prep: dict[str, Any],
    res: dict[str, dict[str, Any]],
    imports: list[list[Any]],
    tgt: list[Target],
    repeats: int,
    total_s: float,
    quick: bool,
) -> None:
    cmd = COMMAND + (" --quick --write-docs" if quick else "")
    head, srows = stage_rows(res)
    lines = [
        "## Geometry speed (`benchmarks/geometry_speed.py`)",
        "",
        f"Latest figures of `benchmarks/geometry_speed.py`. Re-run with `{cmd}`; it rewrites "
        "this section only (the large wall is written to a temporary folder).",
        "",
        "### Machine and run",
        "",
        f"- Date: {info['date']}; rockmech commit: {info['commit']}",
        f"- CPU: {info['cpu']}; nproc = {info['nproc']}; load average (1, 5, 15 min) at "
        f"start: {info['load']}, at the end: {info.get('load_end', '?')}",
        f"- {info['os']}",
        f"- Python {info['python']}, numpy {info['numpy']}, scipy {info['scipy']}, "
        f"rhino3dm {info['rhino3dm']}, manifold3d {info['manifold3d']}, "
        f"shapely {info['shapely']}, pydantic {info['pydantic']}",
        f"- Command: `{cmd}`{' (quick smoke run)' if quick else ''}; whole run "
        f"{total_s / 60:.1f} min",
        "",
        "### Method",
        "",
        "- Walls: the 200k example `examples/scenes/scan_wall.3dm` "
        f"({tri(prep['example_triangles'])} triangles, {prep['example_file_mb']:.1f} MB) and "
        f"a large wall of {tri(prep['large_triangles'])} triangles "
        f"({tri(prep['large_vertices'])} vertices; grid cells {tuple(prep['large_cells'])}), "
        "built with `build_scenes.grid_box_solid` and the example's relief, held in memory and "
        f"written to a {prep['large_file_mb']:.1f} MB `.3dm` with rhino3dm (build "
        f"{fmt_time(prep['large_build_s'])}, write {fmt_time(prep['large_write_s'])}, not "
        "timed further). Spec: `examples/specs/scan_wall.spec.json` (two-sided rocking, "
        "both axes given as line objects).",
        "- In memory: `constants_from_spec(parse_spec(text), scene, ...)` with a `Scene` "
        "subclass whose `mesh` returns a new `TriMesh` of the in-memory arrays (so "
        "`check_solid`'s validity cache never carries over between repeats) and whose `line` "
        "returns the axis end points; everything else is the real code path.",
        "- From .3dm: `Scene.from_3dm`, `parse_spec`, `constants_from_spec` (as "
        "`rockmech constants` does, without writing the JSON). (a) read + mesh = "
        "`Scene.from_3dm` + `Scene.mesh` (called inside `constants_from_spec`), "
        "(b) = `parse_spec` + `constants_from_spec` on the loaded scene, (c) = the total; all "
        "three from the same timed calls.",
        f"- Each case in a fresh subprocess: one cold call, then best of {repeats} warm "
        "calls (`time.perf_counter`), then one call under `tracemalloc`. Stage times come "
        "from timers wrapped around `Scene.from_3dm`, `scene_3dm._mesh_arrays`, "
        "`Scene.mesh`, `check_solid`, `mass_properties` and `rocking_side`, each exclusive of "
        "the stages it calls.",
        "- Memory: `ru_maxrss` of the subprocess after the warm calls (`VmHWM` beside it: on "
        "Linux a child's `ru_maxrss` starts from its parent's peak, so the parent stays "
        "light), and the tracemalloc peak of one call above what was traced before it "
        "(Python objects and numpy buffers; rhino3dm's C++ memory is not traced). MB = "
        "10^6 bytes.",
        "",
        "### Results",
        "",
        md_table(HEAD_CASES, case_rows(prep, res)),
        "",
        "#### Where the time goes (best call of each case)",
        "",
        md_table(head, srows),
        "",
        "#### Memory",
        "",
        md_table(HEAD_MEMORY, memory_rows(res, prep)),
        "",
        "#### First-call overhead (each import timed in a fresh process, in this order)",
        "",
        md_table(["what", "time"], overhead_rows(res, imports)),
        "",
        "#### Same answer on both paths",
        "",
        md_table(HEAD_AGREE, agreement_rows(res)),
        "",
        "### Targets",
        "",
        md_table(
            ["target", "result", "measured"],
            [[name.strip(), verdict(ok), val] for name, ok, val in tgt],
        ),
        "",
        "### Reading",
        "",
        reading(prep, res),
    ]
    write_section(DOC_MD, "geometry_speed", "\n".join(lines))


def main(argv: Optional[list[str]] = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if "--worker" in argv:
        return worker(argv)
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smoke run: one repeat, a 300k wall")
    ap.add_argument(
        "--write-docs", action="store_true", help="write docs/benchmarks.md also in --quick mode"
    )
    args = ap.parse_args(argv)
    quick = bool(args.quick)
    write = (not quick) or args.write_docs
    repeats = QUICK_REPEATS if quick else REPEATS
    cells = QUICK_LARGE_CELLS if quick else LARGE_CELLS
    wall0 = time.perf_counter()
    info = machine_info(
        ("numpy", "scipy", "rhino3dm", "manifold3d", "shapely", "pydantic", "trimesh")
    )
    print(f"rockmech geometry speed benchmark ({'quick' if quick else 'full'} run)")
    print(
        f"{info['date']} | {info['cpu']} | nproc {info['nproc']} | load {info['load']} | "
        f"Python {info['python']} numpy {info['numpy']} rhino3dm {info['rhino3dm']}",
        flush=True,
    )
    res: dict[str, dict[str, Any]] = {}
    with tempfile.TemporaryDirectory(prefix="rockmech-geom-") as tmp:
        data = ["--data", tmp]
        print("\n0. Building the walls (large one also written to .3dm)", flush=True)
        prep = spawn("--worker", "prepare", *data, "--cells", ",".join(map(str, cells)))
        print(
            f"   200k: {tri(prep['example_triangles'])} triangles; large: "
            f"{tri(prep['large_triangles'])} triangles, built in "
            f"{fmt_time(prep['large_build_s'])}, written in {fmt_time(prep['large_write_s'])} "
            f"({prep['large_file_mb']:.1f} MB)",
            flush=True,
        )
        print("1. Import times", flush=True)
        imports = spawn("--worker", "imports", *data)
        for n, (size, kind) in enumerate(
            [("example", "memory"), ("example", "file"), ("large", "memory"), ("large", "file")],
            start=2,
        ):
            print(f"{n}. {size} wall, {kind}", end="", flush=True)
            r = spawn("--worker", kind, *data, "--size", size, "--repeats", str(repeats))
            res[f"{kind}_{size}"] = r
            print(
                f": best {fmt_time(r['best']['total_s'])} (cold {fmt_time(r['cold']['total_s'])}),"
                f" peak RSS {fmt_mb(r['maxrss_mb'])}",
                flush=True,
            )
    parent_rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024 / MB

    print("\n" + "=" * 100)
    print(f"\nCases (best of {repeats} warm calls; each case in a fresh subprocess)")
    print(text_table(HEAD_CASES, case_rows(prep, res)))
    head, srows = stage_rows(res)
    print("\nWhere the time goes (exclusive stage times of the best call)")
    print(text_table(head, srows))
    print("\nMemory (MB = 1e6 bytes)")
    print(text_table(HEAD_MEMORY, memory_rows(res, prep)))
    print(f"(parent process peak RSS {fmt_mb(parent_rss)}: a floor under the workers' ru_maxrss)")
    print("\nFirst-call overhead")
    print(text_table(["what", "time"], overhead_rows(res, imports)))
    print("\nSame answer on both paths")
    print(text_table(HEAD_AGREE, agreement_rows(res)))
    tgt = targets(prep, res)
    print("\nTargets")
    for name, ok, val in tgt:
        print(f"  {verdict(ok)}  {name}: {val}")
    print("\nReading")
    print(reading(prep, res))
    total = time.perf_counter() - wall0
    info["load_end"] = load_average()
    print(f"\nWhole run: {total:.0f} s; load average at the end: {info['load_end']}")
    if write:
        write_docs(info, prep, res, imports, tgt, repeats, total, quick)
        print(f"wrote the geometry_speed section of {DOC_MD.relative_to(REPO)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
