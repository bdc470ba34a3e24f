"""Small ``.3dm`` scenes for the search tests, drawn with the example scenes' builder.

``examples/`` is not a package, so the builder module (``Builder``, ``slab_solid``) is loaded
from its file, as ``tests/cad/cad_scenes.py`` does.
"""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path
from typing import Any, Optional, Sequence

REPO = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location(
    "build_scenes_search", REPO / "examples" / "scenes" / "build_scenes.py"
)
assert _spec is not None and _spec.loader is not None
#: The builder module of the example scenes.
BUILD: Any = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(BUILD)

#: The search example scene and spec.
EXAMPLE_SCENE = REPO / "examples" / "scenes" / "search_facade.3dm"
EXAMPLE_SPEC = REPO / "examples" / "specs" / "search_facade.search.json"


def two_block_wall(
    out: Path,
    b: float = 0.3,
    h: float = 3.0,
    length: float = 1.0,
    name: str = "tb",
    slab_side: float = 1.0,
) -> Path:
    """A wall x in [0, b], y in [0, length], z in [0, h], a slab on top running into +x
    (outer face x = 0), or into -x with ``slab_side = -1`` (outer face x = b)."""
    bld = BUILD.Builder(name)
    bld.box("wall", "Walls", (0.0, 0.0, 0.0), (b, length, h), "brick")
    x0, x1 = (0.0, 3.0) if slab_side > 0 else (b - 3.0, b)
    bld.box("slab", "Floors", (x0, 0.0, h), (x1, length, h + 0.2), "concrete")
    return bld.write(out / f"{name}.3dm")


def wedge_facade(
    out: Path,
    H: float = 9.0,
    L: float = 8.0,
    t: float = 0.5,
    s: float = 0.5,
    reach: float = 12.0,
    windows: Sequence[tuple[float, float, float, float]] = (),
    mirror: bool = False,
    scale: float = 1.0,
    name: str = "wedge",
) -> Path:
    """A façade (outer face x = 0) between two return walls running into +x.

    ``mirror`` reflects the scene in the plane y = 0; ``scale`` scales every length.
    """
    bld = BUILD.Builder(name)
    k = scale
    sy = -1.0 if mirror else 1.0

    def box(nm: str, lo: tuple[float, float, float], hi: tuple[float, float, float]) -> None:
        y0, y1 = sorted((sy * lo[1], sy * hi[1]))
        bld.box(
            nm, "Walls", (k * lo[0], k * y0, k * lo[2]), (k * hi[0], k * y1, k * hi[2]), "brick"
        )

    holes = [
        [(k * a, k * c), (k * b, k * c), (k * b, k * d), (k * a, k * d)] for a, b, c, d in windows
    ]
    v, f = BUILD.slab_solid(
        (0.0, 0.0, 0.0),
        (0.0, sy, 0.0),
        (1.0, 0.0, 0.0),
        k * t,
        [(0.0, 0.0), (k * L, 0.0), (k * L, k * H), (0.0, k * H)],
        holes,
    )
    bld.mesh("facade", "Walls", v, f, "brick")
    box("left", (t, 0.0, 0.0), (t + reach, s, H))
    box("right", (t, L - s, 0.0), (t + reach, L, H))
    return bld.write(out / f"{name}.3dm")


def write_spec(path: Path, doc: dict[str, Any]) -> Path:
    """Write a search spec (JSON)."""
    path.write_text(json.dumps(doc, indent=1))
    return path


def wedge_spec(
    connection: str = "good",
    unit: Optional[tuple[float, float]] = (0.25, 0.12),
    families: Optional[list[str]] = None,
    **extra: Any,
) -> dict[str, Any]:
    """The search spec of ``wedge_facade``: three walls of 1800 kg/m³, one connection."""
    junction: dict[str, Any] = {"connection": connection}
    if unit is not None:
        junction["unit"] = {"length": unit[0], "height": unit[1]}
    doc: dict[str, Any] = {
        "walls": [
            {"id": "F", "object": "facade", "density": 1800.0},
            {"id": "L", "object": "left", "density": 1800.0, "facade": False},
            {"id": "R", "object": "right", "density": 1800.0, "facade": False},
        ],
        "default_junction": junction,
        "directions": ["outward"],
    }
    if families is not None:
        doc["families"] = families
    doc.update(extra)
    return doc


def three_storey_facade(out: Path, name: str = "storeys") -> Path:
    """A three-storey façade (outer face x = 0; 8 m long, 10.5 m high, 0.5 m thick), two
    return walls and a back wall, and three 0.2 m floors abutting its inner face at 3.5 m,
    7 m and 10.3 m (the last one at the top)."""
    t, length, h, reach, w = 0.5, 8.0, 10.5, 6.0, 0.45
    bld = BUILD.Builder(name)
    bld.box("facade", "Walls", (0.0, 0.0, 0.0), (t, length, h), "brick")
    bld.box("left", "Walls", (t, 0.0, 0.0), (t + reach, w, h), "brick")
    bld.box("right", "Walls", (t, length - w, 0.0), (t + reach, length, h), "brick")
    bld.box("back", "Walls", (t + reach, 0.0, 0.0), (2 * t + reach, length, h), "brick")
    for nm, z in (("floor_1", 3.5), ("floor_2", 7.0), ("floor_3", 10.3)):
        bld.box(nm, "Floors", (t, w + 0.01, z), (t + reach, length - w - 0.01, z + 0.2), "concrete")
    return bld.write(out / f"{name}.3dm")


def three_storey_spec(**extra: Any) -> dict[str, Any]:
    """The search spec of ``three_storey_facade``: poor junctions, the façade's overturning."""
    doc: dict[str, Any] = {
        "walls": [
            {"id": "F", "object": "facade", "density": 1800.0},
            {"id": "L", "object": "left", "density": 1800.0, "facade": False},
            {"id": "R", "object": "right", "density": 1800.0, "facade": False},
            {"id": "B", "object": "back", "density": 1800.0, "facade": False},
        ],
        "levels": [
            {"id": "f1", "kind": "floor", "objects": ["floor_1"], "density": 2400.0,
             "tributary": 0.5},
            {"id": "f2", "kind": "floor", "objects": ["floor_2"], "density": 2400.0,
             "tributary": 0.5},
            {"id": "f3", "kind": "floor", "objects": ["floor_3"], "density": 2400.0,
             "tributary": 0.5},
        ],
        "default_junction": {"connection": "poor"},
        "families": ["overturning", "partial_overturning", "parapet"],
        "directions": ["outward"],
        "lp": False,
    }  # fmt: skip
    doc.update(extra)
    return doc


Plan2 = Sequence[tuple[float, float]]


def ring_walls(ring: Plan2, t: float, prefix: str) -> list[tuple[str, Any, Any, float]]:
    """The walls along a ring of outer-face corners, material on the left of each edge.

    At a left turn (a convex corner of the material) the incoming wall runs to the corner and
    the next one butts on its inner face; at a right turn (re-entrant) the incoming wall runs
    on by ``t`` and the next one stands on its outer face. Returns (id, start, end, t): the
    outer-face line of each wall, in plan [m].
    """
    import numpy as np

    pts = [np.asarray(p, dtype=float) for p in ring]
    n = len(pts)
    out = []
    for i in range(n):
        a, b = pts[i], pts[(i + 1) % n]
        d = (b - a) / float(np.linalg.norm(b - a))
        prev, nxt = pts[i - 1], pts[(i + 2) % n]

        def left_turn(p: Any, q: Any, r: Any) -> bool:
            return float((q - p)[0] * (r - q)[1] - (q - p)[1] * (r - q)[0]) > 0.0

        start = a + (t * d if left_turn(prev, a, b) else 0.0)
        end = b + (0.0 if left_turn(a, b, nxt) else t * d)
        out.append((f"{prefix}{i}", start, end, t))
    return out


#: A closed mesh of a plan polygon with holes extruded in z (the builder's ``plan_prism``).
plan_prism = BUILD.plan_prism


def plan_scene(
    out: Path,
    walls: Sequence[tuple[str, Any, Any, float]],
    h: float,
    *,
    rotate_deg: float = 0.0,
    shift: tuple[float, float] = (0.0, 0.0),
    mirror: bool = False,
    slabs: Sequence[tuple[str, Plan2, Sequence[Plan2], float, float]] = (),
    name: str = "plan",
    heights: Optional[dict[str, tuple[float, float]]] = None,
    footprints: Sequence[tuple[str, Plan2]] = (),
) -> Path:
    """Walls (id, outer-face start, end, thickness; material on the left) of height ``h``.

    ``footprints`` are more walls (id, plan polygon) drawn as prisms from 0 to ``h`` (oblique
    or mitred ends). ``heights`` gives some walls their own base and top ``(z0, z1)`` [m] instead of
    ``(0, h)``. ``slabs`` are horizontal levels (id, outline, holes, z0, z1). The whole scene
    is mirrored in x = 0 (``mirror``), turned by ``rotate_deg`` about the vertical through
    the origin, then moved by ``shift`` [m].
    """
    import math

    import numpy as np

    c, s = math.cos(math.radians(rotate_deg)), math.sin(math.radians(rotate_deg))
    rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    flip = np.diag([-1.0, 1.0, 1.0]) if mirror else np.eye(3)
    move = np.array([shift[0], shift[1], 0.0])

    def place(v: Any) -> Any:
        return v @ flip.T @ rot.T + move

    bld = BUILD.Builder(name)
    for wid, a, b, t in walls:
        a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
        length = float(np.linalg.norm(b - a))
        e_s = (b - a) / length
        e_n = np.array([-e_s[1], e_s[0]])
        z0, z1 = (heights or {}).get(wid, (0.0, h))
        v, f = BUILD.slab_solid(
            (a[0], a[1], z0),
            (e_s[0], e_s[1], 0.0),
            (e_n[0], e_n[1], 0.0),
            t,
            [(0.0, 0.0), (length, 0.0), (length, z1 - z0), (0.0, z1 - z0)],
        )
        v = place(v)
        if mirror:
            f = f[:, ::-1]
        bld.mesh(wid, "Walls", np.ascontiguousarray(v), np.ascontiguousarray(f), "brick")
    for wid, ring in footprints:
        v, f = plan_prism(ring, [], 0.0, h)
        v = place(v)
        if mirror:
            f = f[:, ::-1]
        bld.mesh(wid, "Walls", np.ascontiguousarray(v), np.ascontiguousarray(f), "brick")
    for sid, outline, holes, z0, z1 in slabs:
        v, f = plan_prism(outline, holes, z0, z1)
        v = place(v)
        if mirror:
            f = f[:, ::-1]
        bld.mesh(sid, "Floors", np.ascontiguousarray(v), np.ascontiguousarray(f), "concrete")
    return bld.write(out / f"{name}.3dm")


def plan_spec(
    ids: Sequence[str], connection: str = "poor", levels: Sequence[str] = (), **extra: Any
) -> dict[str, Any]:
    """A search spec for ``plan_scene``: every wall a façade of 1800 kg/m³, one connection."""
    doc: dict[str, Any] = {
        "walls": [{"id": i, "object": i, "density": 1800.0} for i in ids],
        "default_junction": {"connection": connection, "unit": {"length": 0.25, "height": 0.12}},
        "directions": ["outward"],
        "families": ["overturning", "wedge_overturning"],
    }
    if levels:
        doc["levels"] = [
            {"id": lv, "objects": [lv], "density": 600.0, "kind": "floor"} for lv in levels
        ]
    doc.update(extra)
    return doc


def cli_refusal(scene: Path, spec: Path, out: Path) -> str:
    """Run ``rockmech search`` on input it must refuse; return its one error line.

    The command exits with 2, prints no traceback and one ``error: ...`` line, and writes
    no ``search.json``.
    """
    from typer.testing import CliRunner

    from solver_service.cli import app

    res = CliRunner().invoke(app, ["search", str(scene), str(spec), "-o", str(out / "o")])
    assert res.exit_code == 2, res.output
    assert "Traceback" not in res.stderr
    lines = [ln for ln in res.stderr.splitlines() if ln.startswith("error: ")]
    assert len(lines) == 1, res.stderr
    assert not (out / "o" / "search.json").exists()
    return lines[0]
