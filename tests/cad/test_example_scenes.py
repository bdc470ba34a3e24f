"""The example .3dm scenes: readable, as documented, closed solids, and reproducible."""

import importlib.util
import re
import uuid
from pathlib import Path
from types import ModuleType
from typing import Dict, List, Tuple

import numpy as np
import pytest

pytest.importorskip("rhino3dm")

from cad_maths.geometry.mesh import TriMesh
from cad_maths.scene_3dm import Scene

SCENES = Path(__file__).resolve().parents[2] / "examples" / "scenes"
FILES = [
    "rect_wall.3dm",
    "statue_column.3dm",
    "facade.3dm",
    "scan_wall.3dm",
    "two_block_wall.3dm",
    "side_aisle.3dm",
    "portal_frame.3dm",
    "asym_frame.3dm",
    "search_facade.3dm",
]
#: Scan-mesh examples (binary PLY in mm) that build_scenes.py writes too.
SCANS = ["scan_wall.ply"]
SOLID_KINDS = ("mesh", "brep", "extrusion")
# Namespace of the fixed object ids, as documented in the README.
ID_NAMESPACE = uuid.UUID("6f1c2a52-0d0e-4c8b-9a57-3d1e2b7a9c40")
# Exact volumes [m^3] of the planar-faced solids.
VOLUMES = {
    ("rect_wall.3dm", "wall"): 0.5 * 1.0 * 3.0,
    ("facade.3dm", "facade"): 0.6 * 6 * 8 - 0.35 * 0.3 * 6,
    ("facade.3dm", "side_wall_left"): 5.0 * 0.6 * 8,
    ("facade.3dm", "back_wall"): 0.6 * 6 * 8,
    ("facade.3dm", "floor_bearing"): 5.3 * 4.8 * 0.2,
    ("facade.3dm", "floor_abutting"): 5.0 * 4.8 * 0.2,
    ("facade.3dm", "roof"): 0.5 * 6.2 * 1.6 * 6,
    ("facade.3dm", "vault"): 5.0 * 0.3 * 4.8,
    ("statue_column.3dm", "column"): 0.5 * 24 * 0.3**2 * np.sin(2 * np.pi / 24) * 3.0,
    ("two_block_wall.3dm", "wall"): 0.3 * 3.0 * 4.0,
    ("two_block_wall.3dm", "floor"): 4.0 * 3.0 * 0.2,
    ("side_aisle.3dm", "wall"): 0.6 * 5.0 * 4.0,
    ("side_aisle.3dm", "vault"): (0.3 + 4.0 + 0.45) * 0.3 * 4.0,
    ("side_aisle.3dm", "pier"): 0.45 * 5.0 * 4.0,
    ("portal_frame.3dm", "column_left"): 0.5 * 4.0,
    ("portal_frame.3dm", "beam"): 4.0 * 0.5,
    ("portal_frame.3dm", "column_right"): 0.5 * 4.0,
    ("asym_frame.3dm", "column_left"): 0.5 * 4.0,
    ("asym_frame.3dm", "beam"): 4.2 * 0.5,
    ("asym_frame.3dm", "column_right"): 0.7 * 3.6,
    ("search_facade.3dm", "facade"): 0.5 * (8.0 * 10.5 - 2 * 1.2 * (2.0 + 1.8 + 1.6)),
    ("search_facade.3dm", "return_left"): 6.0 * 0.45 * 10.5,
    ("search_facade.3dm", "back_wall"): 0.5 * 8.0 * 10.5,
    ("search_facade.3dm", "floor_1"): 6.0 * 7.08 * 0.2,
}
# Hinge lines of the four-bar scenes: (x, z) of A, B, C, D, positive set then mirrored set;
# each runs along y over the scene's length.
HINGES = {
    "side_aisle.3dm": (
        4.0,
        [(0.6, 0), (0.3, 5), (4.6, 5), (5.05, 0)],
        [(0, 0), (0.6, 5), (5.05, 5), (4.6, 0)],
    ),
    "portal_frame.3dm": (
        1.0,
        [(0.5, 0), (0, 4), (3.5, 4), (4, 0)],
        [(0, 0), (0.5, 4), (4, 4), (3.5, 0)],
    ),
    "asym_frame.3dm": (
        1.0,
        [(0.5, 0), (0, 4), (3.5, 3.6), (4.2, 0)],
        [(0, 0), (0.5, 4), (4.2, 3.6), (3.5, 0)],
    ),
}


def readme_rows() -> Dict[str, List[Tuple[str, str, str]]]:
    """(name, layer, kind) rows of each scene's table in README.md."""
    rows: Dict[str, List[Tuple[str, str, str]]] = {}
    current = None
    for line in (SCENES / "README.md").read_text(encoding="utf-8").splitlines():
        head = re.match(r"^### (\S+)", line)
        if head:  # a .3dm scene's table; other sections (the scan) are not rows of one
            current = head.group(1) if head.group(1).endswith(".3dm") else None
            if current:
                rows[current] = []
        row = re.match(r"^\| `([^`]+)` \| `([^`]+)` \| (\w+) \|", line)
        if row and current:
            rows[current].append((row.group(1), row.group(2), row.group(3)))
    return rows


def volume(mesh: TriMesh) -> float:
    v, f = mesh.vertices, mesh.faces
    return float(np.einsum("ij,ij->i", v[f[:, 0]], np.cross(v[f[:, 1]], v[f[:, 2]])).sum() / 6)


def is_watertight(mesh: TriMesh) -> bool:
    f = mesh.faces
    e = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    key = e[:, 0] * (mesh.vertices.shape[0] + 1) + e[:, 1]
    und = np.minimum(e[:, 0], e[:, 1]) * (mesh.vertices.shape[0] + 1) + np.maximum(e[:, 0], e[:, 1])
    _, n_dir = np.unique(key, return_counts=True)
    _, n_und = np.unique(und, return_counts=True)
    return bool(np.all(n_dir == 1) and np.all(n_und == 2))


def load_builder() -> ModuleType:
    spec = importlib.util.spec_from_file_location("build_scenes", SCENES / "build_scenes.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def geometry(scene: Scene) -> Dict[str, object]:
    """What each named object is, in metres: meshes, line ends, planes, plus its metadata."""
    out: Dict[str, object] = {}
    for obj in scene.objects:
        meta = (obj.id, obj.layer, obj.kind, tuple(sorted(obj.user_text.items())))
        if obj.kind in SOLID_KINDS:
            mesh = scene.mesh(obj)
            out[obj.name] = (meta, mesh.vertices, mesh.faces)
        elif obj.kind == "line":
            out[obj.name] = (meta, *scene.line(obj))
        else:
            out[obj.name] = (meta, *scene.plane(obj))
    return out


@pytest.fixture(scope="module")
def committed() -> Dict[str, Scene]:
    return {name: Scene.from_3dm(SCENES / name) for name in FILES}


@pytest.fixture(scope="module")
def committed_geometry(committed: Dict[str, Scene]) -> Dict[str, Dict[str, object]]:
    return {name: geometry(scene) for name, scene in committed.items()}


def test_readme_documents_every_scene() -> None:
    rows = readme_rows()
    assert sorted(rows) == sorted(FILES)
    assert all(rows[name] for name in FILES)


@pytest.mark.parametrize("name", FILES)
def test_every_documented_object_is_found_as_documented(
    name: str, committed: Dict[str, Scene]
) -> None:
    scene = committed[name]
    assert scene.units == "meters" and scene.unit_scale == 1.0
    documented = readme_rows()[name]
    for obj_name, layer, kind in documented:
        (obj,) = scene.find(obj_name)
        assert (obj.layer, obj.kind) == (layer, kind), obj_name
        assert scene.find({"id": obj.id}) == [obj]
        assert obj.id == str(uuid.uuid5(ID_NAMESPACE, f"{name[:-4]}/object/{obj_name}"))
    assert sorted(o.name for o in scene.objects) == sorted(n for n, _, _ in documented)


@pytest.mark.parametrize("name", FILES)
def test_solids_are_watertight_with_positive_volume(
    name: str, committed: Dict[str, Scene], committed_geometry: Dict[str, Dict[str, object]]
) -> None:
    scene = committed[name]
    for obj in scene.objects:
        if obj.kind not in SOLID_KINDS:
            continue
        _, v, f = committed_geometry[name][obj.name]  # type: ignore[misc]
        mesh = TriMesh(v, f, obj.name)
        assert is_watertight(mesh), obj.label()
        vol = volume(mesh)
        assert vol > 0.0, obj.label()
        if (name, obj.name) in VOLUMES:
            assert vol == pytest.approx(VOLUMES[name, obj.name], rel=1e-12), obj.label()


def test_scan_wall_is_a_large_irregular_mesh(
    committed_geometry: Dict[str, Dict[str, object]],
) -> None:
    _, v, f = committed_geometry["scan_wall.3dm"]["scan_wall"]  # type: ignore[misc]
    assert f.shape[0] >= 200_000
    assert (SCENES / "scan_wall.3dm").stat().st_size < 15e6
    x = v[:, 0]
    assert x.min() < -0.005 and x.max() > 0.605  # relief on both large faces
    base = v[v[:, 2] == 0.0]
    assert set(np.unique(base[:, 0])) == {0.0, 0.6}  # straight bottom edges


#: Scenes without axes: the search finds its mechanisms' axes itself.
NO_AXES = ("search_facade.3dm",)


@pytest.mark.parametrize("name", [n for n in FILES if n not in HINGES and n not in NO_AXES])
def test_axes_lie_on_the_base_of_the_body(
    name: str, committed: Dict[str, Scene], committed_geometry: Dict[str, Dict[str, object]]
) -> None:
    scene = committed[name]
    body = scene.objects[0]
    _, v, _ = committed_geometry[name][body.name]  # type: ignore[misc]
    for axis in scene.find({"layer": "Axes"}):
        start, end = scene.line(axis)
        assert start[2] == end[2] == v[:, 2].min() == 0.0
        u = (end - start) / np.linalg.norm(end - start)
        d = v - start
        dist = np.linalg.norm(d - np.outer(d @ u, u), axis=1)
        assert dist.min() < 1e-12, axis.label()


def test_facade_elements_touch_the_facade_as_described(
    committed_geometry: Dict[str, Dict[str, object]],
) -> None:
    g = committed_geometry["facade.3dm"]
    lo = {k: g[k][1].min(0) for k in g if g[k][0][2] in SOLID_KINDS}  # type: ignore[index]
    assert lo["floor_bearing"][2] == 3.5 and lo["floor_abutting"][0] == 0.6
    assert lo["vault"][0] == 0.6 and lo["vault"][2] == 4.0 and lo["roof"][2] == 8.0
    for tie in ("tie_1", "tie_2"):
        assert g[tie][1][0] == 0.0  # type: ignore[index]
    point, normal = g["crack"][1], g["crack"][2]  # type: ignore[index]
    np.testing.assert_allclose(abs(normal @ np.array([0, 1, 1]) / np.sqrt(2)), 1.0, atol=1e-12)
    assert (np.array([0.3, 1.0, 8.0]) - point) @ normal == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("name", sorted(HINGES))
def test_hinge_lines_are_edges_of_the_solids(
    name: str, committed: Dict[str, Scene], committed_geometry: Dict[str, Dict[str, object]]
) -> None:
    scene = committed[name]
    length, positive, negative = HINGES[name]
    corners = np.vstack(
        [
            committed_geometry[name][o.name][1]  # type: ignore[index]
            for o in scene.objects
            if o.kind in SOLID_KINDS
        ]
    )
    for suffix, points in (("", positive), ("_neg", negative)):
        for label, (x, z) in zip("ABCD", points):
            (obj,) = scene.find(f"hinge_{label}{suffix}")
            start, end = scene.line(obj)
            np.testing.assert_allclose(start, [x, 0.0, z], rtol=0, atol=1e-12)
            np.testing.assert_allclose(end, [x, length, z], rtol=0, atol=1e-12)
            # both ends are vertices of a solid: the hinge is an edge of the blocks
            for p in (start, end):
                assert np.linalg.norm(corners - p, axis=1).min() < 1e-12, obj.label()


def test_build_script_is_deterministic(
    tmp_path: Path, committed_geometry: Dict[str, Dict[str, object]]
) -> None:
    paths = load_builder().build_all(tmp_path)
    assert sorted(p.name for p in paths) == sorted([*FILES, *SCANS])
    for name in SCANS:  # the header and the faces byte for byte, the vertices to the last bits
        new, old = (tmp_path / name).read_bytes(), (SCENES / name).read_bytes()
        start = new.index(b"end_header\n") + len(b"end_header\n")
        assert new[:start] == old[:start] and len(new) == len(old), name
        n_v = int(re.search(rb"element vertex (\d+)", new[:start]).group(1))  # type: ignore[union-attr]
        end = start + 24 * n_v
        assert new[end:] == old[end:], name
        np.testing.assert_allclose(
            np.frombuffer(new[start:end], "<f8"), np.frombuffer(old[start:end], "<f8"), atol=1e-9
        )
    for name in FILES:
        rebuilt = geometry(Scene.from_3dm(tmp_path / name))
        old = committed_geometry[name]
        assert sorted(rebuilt) == sorted(old), name
        for obj_name, new in rebuilt.items():
            ref = old[obj_name]
            assert new[0] == ref[0], (name, obj_name)  # type: ignore[index]
            for a, b in zip(new[1:], ref[1:]):  # type: ignore[index]
                if np.asarray(a).dtype.kind == "i":
                    np.testing.assert_array_equal(a, b)
                else:  # libm may differ in the last bit between machines
                    np.testing.assert_allclose(a, b, rtol=0, atol=1e-12)
