"""Headless .3dm reading: solids, units, selection, lines and planes.

Each test writes a small .3dm file with rhino3dm and reads it back. Volumes are checked
against the exact value with the signed-tetrahedra sum computed here, not by the code
under test.
"""

import math
import subprocess
import sys
import textwrap
import uuid
from pathlib import Path
from typing import List, Sequence, Tuple

import numpy as np
import pytest

r3 = pytest.importorskip("rhino3dm")
hypothesis = pytest.importorskip("hypothesis")
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from cad_maths.geometry.mesh import TriMesh  # noqa: E402
from cad_maths.geometry.polygon import triangulate_polygon  # noqa: E402
from cad_maths.scene_3dm import Scene, SceneObject  # noqa: E402
from shared_schema.errors import GeometryError, InputError  # noqa: E402

P = r3.Point3d


# ---------------------------------------------------------------- helpers


def volume(mesh: TriMesh) -> float:
    v, f = mesh.vertices, mesh.faces
    return float(np.einsum("ij,ij->i", v[f[:, 0]], np.cross(v[f[:, 1]], v[f[:, 2]])).sum() / 6)


def is_watertight(mesh: TriMesh) -> bool:
    """Every edge used by exactly two triangles, once in each direction."""
    f = mesh.faces
    e = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    _, n_dir = np.unique(e, axis=0, return_counts=True)
    _, n_und = np.unique(np.sort(e, axis=1), axis=0, return_counts=True)
    return bool(np.all(n_dir == 1) and np.all(n_und == 2))


def attrs(name: str, layer: int = 0, **text: str) -> "r3.ObjectAttributes":
    a = r3.ObjectAttributes()
    a.Name = name
    a.LayerIndex = layer
    for k, v in text.items():
        a.SetUserString(k, v)
    return a


def new_model(units: "r3.UnitSystem" = None) -> "r3.File3dm":
    model = r3.File3dm()
    model.Settings.ModelUnitSystem = units if units is not None else r3.UnitSystem.Meters
    return model


def write(model: "r3.File3dm", path: Path) -> Scene:
    assert model.Write(str(path), 8)
    return Scene.from_3dm(path)


def box_mesh(lo: Sequence[float], hi: Sequence[float], flip_one: bool = False) -> "r3.Mesh":
    """A box as Rhino makes it: 6 quads, 24 unwelded vertices, outward winding."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    quads = [
        [(x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)],  # bottom, -z
        [(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)],  # top, +z
        [(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)],  # -y
        [(x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0)],  # +y
        [(x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)],  # -x
        [(x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)],  # +x
    ]
    m = r3.Mesh()
    for k, q in enumerate(quads):
        if flip_one and k == 3:
            q = q[::-1]
        base = len(m.Vertices)
        for x, y, z in q:
            m.Vertices.AddPoint3d(x, y, z)
        m.Faces.AddFace(base, base + 1, base + 2, base + 3)
    return m


def box(lo: Sequence[float], hi: Sequence[float]) -> "r3.Box":
    return r3.Box(r3.BoundingBox(*lo, *hi))


def prism(profile: List[Tuple[float, float]], y0: float, y1: float) -> "r3.Extrusion":
    """Extrusion of an x-z profile from y = y1 to y = y0 (profile x, y -> world x, z)."""
    pts = [P(x, z, 0.0) for x, z in profile] + [P(profile[0][0], profile[0][1], 0.0)]
    ext = r3.Extrusion()
    assert ext.SetOuterProfile(r3.Polyline(pts).ToPolylineCurve(), True)
    assert ext.SetPathAndUp(P(0.0, y1, 0.0), P(0.0, y0, 0.0), r3.Vector3d(0.0, 0.0, 1.0))
    return ext


LO, HI = (0.25, -1.5, 0.125), (0.75, 2.5, 3.625)  # exact binary fractions
BOX_VOLUME = 0.5 * 4.0 * 3.5


# ---------------------------------------------------------------- solids


@pytest.mark.parametrize("kind", ["mesh", "brep", "extrusion"])
def test_box_is_watertight_with_exact_positive_volume(tmp_path: Path, kind: str) -> None:
    model = new_model()
    if kind == "mesh":
        model.Objects.AddMesh(box_mesh(LO, HI), attrs("box"))
    elif kind == "brep":
        model.Objects.AddBrep(r3.Brep.CreateFromBox(box(LO, HI)), attrs("box"))
    else:
        model.Objects.AddExtrusion(r3.Extrusion.CreateBoxExtrusion(box(LO, HI), True), attrs("box"))
    scene = write(model, tmp_path / "box.3dm")
    obj = scene.find("box")[0]
    assert obj.kind == kind
    mesh = scene.mesh(obj)
    assert mesh.vertices.dtype == np.float64 and mesh.vertices.shape == (8, 3)
    assert mesh.n_triangles == 12
    assert is_watertight(mesh)
    assert volume(mesh) == pytest.approx(BOX_VOLUME, rel=1e-12)
    np.testing.assert_array_equal(mesh.vertices.min(0), LO)
    np.testing.assert_array_equal(mesh.vertices.max(0), HI)
    assert mesh.name == "box"
    assert mesh.meta == {"id": obj.id, "layer": obj.layer, "kind": kind}


def wall_with_window() -> "r3.Extrusion":
    """Wall x in [0, 0.5], y in [0, 4], z in [0, 3] with a 1.0 x 1.25 m window through x."""
    outer = [P(0, 0, 0), P(4, 0, 0), P(4, 3, 0), P(0, 3, 0), P(0, 0, 0)]
    hole = [P(1.5, 1, 0), P(2.5, 1, 0), P(2.5, 2.25, 0), P(1.5, 2.25, 0), P(1.5, 1, 0)]
    ext = r3.Extrusion()
    assert ext.SetOuterProfile(r3.Polyline(outer).ToPolylineCurve(), True)
    assert ext.AddInnerProfile(r3.Polyline(hole).ToPolylineCurve())
    # profile (x, y) -> world (y, z), extruded along +x
    assert ext.SetPathAndUp(P(0, 0, 0), P(0.5, 0, 0), r3.Vector3d(0, 0, 1))
    return ext


@pytest.mark.parametrize("as_brep", [False, True])
def test_wall_with_window_has_box_minus_opening_volume(tmp_path: Path, as_brep: bool) -> None:
    model = new_model()
    ext = wall_with_window()
    if as_brep:
        brep = ext.ToBrep(True)
        inner = sum(
            1
            for face in brep.Faces
            for k in range(len(face.Loops))
            if face.Loops[k].LoopType == r3.BrepLoopType.Inner
        )
        assert inner == 2  # both large faces carry the window as an inner loop
        model.Objects.AddBrep(brep, attrs("wall"))
    else:
        model.Objects.AddExtrusion(ext, attrs("wall"))
    scene = write(model, tmp_path / "window.3dm")
    mesh = scene.mesh(scene.find("wall")[0])
    bb = (mesh.vertices.min(0), mesh.vertices.max(0))
    np.testing.assert_allclose(bb[0], [0, 0, 0], atol=1e-15)
    np.testing.assert_allclose(bb[1], [0.5, 4, 3], atol=1e-15)
    assert is_watertight(mesh)
    assert volume(mesh) == pytest.approx(0.5 * (4 * 3 - 1.0 * 1.25), rel=1e-12)


def test_non_convex_prism_with_collinear_vertices(tmp_path: Path) -> None:
    # façade-like section with a pocket, plus a vertex in the middle of the outer edge
    profile = [
        (0, 0),
        (0.6, 0),
        (0.6, 3.5),
        (0.25, 3.5),
        (0.25, 3.75),
        (0.6, 3.75),
        (0.6, 8),
        (0, 8),
        (0, 4),
    ]
    area = 0.6 * 8 - 0.35 * 0.25
    model = new_model()
    model.Objects.AddExtrusion(prism(profile, 0.0, 6.0), attrs("facade"))
    scene = write(model, tmp_path / "f.3dm")
    mesh = scene.mesh(scene.objects[0])
    assert is_watertight(mesh)
    assert volume(mesh) == pytest.approx(area * 6.0, rel=1e-12)


def test_millimetre_file_is_read_in_metres(tmp_path: Path) -> None:
    model = new_model(r3.UnitSystem.Millimeters)
    model.Objects.AddBrep(r3.Brep.CreateFromBox(box((0, 0, 0), (500, 1000, 3000))), attrs("wall"))
    model.Objects.AddLine(P(500, 0, 0), P(500, 1000, 0), attrs("axis"))
    scene = write(model, tmp_path / "mm.3dm")
    assert scene.units == "millimeters"
    assert scene.unit_scale == pytest.approx(1e-3, rel=1e-15)
    mesh = scene.mesh(scene.find("wall")[0])
    np.testing.assert_array_equal(mesh.vertices.max(0), [0.5, 1.0, 3.0])
    assert volume(mesh) == pytest.approx(1.5, rel=1e-12)
    start, end = scene.line(scene.find("axis")[0])
    np.testing.assert_array_equal(start, [0.5, 0.0, 0.0])
    np.testing.assert_array_equal(end, [0.5, 1.0, 0.0])


def test_inch_file_is_read_in_metres(tmp_path: Path) -> None:
    model = new_model(r3.UnitSystem.Inches)
    model.Objects.AddLine(P(0, 0, 0), P(100, 0, 0), attrs("tie"))
    scene = write(model, tmp_path / "in.3dm")
    _, end = scene.line(scene.find("tie")[0])
    assert end[0] == pytest.approx(2.54, rel=1e-15)


def test_curved_brep_without_render_mesh_names_object_and_fix(tmp_path: Path) -> None:
    model = new_model()
    sphere = r3.Brep.CreateFromSphere(r3.Sphere(P(0, 0, 5), 1.0))
    model.Objects.AddBrep(sphere, attrs("dome"))
    cylinder = r3.Brep.CreateFromCylinder(r3.Cylinder(r3.Circle(0.3), 3.0), True, True)
    model.Objects.AddBrep(cylinder, attrs("column"))
    ext = r3.Extrusion.CreateCylinderExtrusion(r3.Cylinder(r3.Circle(0.3), 3.0), True, True)
    model.Objects.AddExtrusion(ext, attrs("drum"))
    scene = write(model, tmp_path / "curved.3dm")
    for name in ("dome", "column", "drum"):
        with pytest.raises(GeometryError) as err:
            scene.mesh(scene.find(name)[0])
        msg = str(err.value)
        assert name in msg
        assert "curved" in msg
        assert "Mesh command" in msg and "render meshes" in msg


_RENDER_MESH_WRITER = textwrap.dedent(
    """
    import math, os, sys
    import rhino3dm as r
    N, R, H = 16, 0.75, 2.5
    brep = r.Brep.CreateFromCylinder(r.Cylinder(r.Circle(R), H), True, True)
    ring = [(R * math.cos(2 * math.pi * k / N), R * math.sin(2 * math.pi * k / N))
            for k in range(N)]
    keep = []
    for i in range(len(brep.Faces)):
        face = brep.Faces[i]
        m = r.Mesh()
        if face.IsPlanar():
            z = face.PointAt(face.Domain(0).T0, face.Domain(1).T0).Z
            m.Vertices.AddPoint3d(0.0, 0.0, z)
            for x, y in ring:
                m.Vertices.AddPoint3d(x, y, z)
            for k in range(N):
                m.Faces.AddFace(0, 1 + k, 1 + (k + 1) % N)
        else:
            for z in (0.0, H):
                for x, y in ring:
                    m.Vertices.AddPoint3d(x, y, z)
            for k in range(N):
                m.Faces.AddFace(k, (k + 1) % N, N + (k + 1) % N, N + k)
        keep.append(m)
        face.SetMesh(m, r.MeshType.Render)
    # an Extrusion stores one render mesh for the whole object: caps and side together
    ext = r.Extrusion.CreateCylinderExtrusion(r.Cylinder(r.Circle(R), H), True, True)
    whole = r.Mesh()
    for z in (0.0, H):
        whole.Vertices.AddPoint3d(0.0, 0.0, z)
        for x, y in ring:
            whole.Vertices.AddPoint3d(x, y, z)
    for k in range(N):
        k1 = (k + 1) % N
        whole.Faces.AddFace(0, 1 + k1, 1 + k)
        whole.Faces.AddFace(N + 1, N + 2 + k, N + 2 + k1)
        whole.Faces.AddFace(1 + k, 1 + k1, N + 2 + k1, N + 2 + k)
    keep.append(whole)
    ext.SetMesh(whole, r.MeshType.Render)
    model = r.File3dm()
    model.Settings.ModelUnitSystem = r.UnitSystem.Meters
    a = r.ObjectAttributes()
    a.Name = "column"
    model.Objects.AddBrep(brep, a)
    a = r.ObjectAttributes()
    a.Name = "drum"
    model.Objects.AddExtrusion(ext, a)
    ok = model.Write(sys.argv[1], 8)
    sys.stdout.write("ok" if ok else "failed")
    sys.stdout.flush()
    # rhino3dm frees a mesh given to BrepFace.SetMesh twice at exit (its known bug): skip it
    os._exit(0)
    """
)


def test_curved_brep_and_extrusion_use_stored_render_meshes(tmp_path: Path) -> None:
    path = tmp_path / "render.3dm"
    out = subprocess.run(
        [sys.executable, "-c", _RENDER_MESH_WRITER, str(path)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert out.stdout == "ok", out.stderr
    scene = Scene.from_3dm(path)
    n, radius, height = 16, 0.75, 2.5
    exact = 0.5 * n * radius**2 * math.sin(2 * math.pi / n) * height
    # Brep: caps and side are stored per face; welding makes one closed solid
    for name in ("column", "drum"):
        mesh = scene.mesh(scene.find(name)[0])
        assert is_watertight(mesh), name
        assert volume(mesh) == pytest.approx(exact, rel=1e-12), name


def test_planar_face_with_curved_edge_is_sampled_along_the_edge(tmp_path: Path) -> None:
    model = new_model()
    disk = r3.Brep.CreateTrimmedPlane(r3.Plane.WorldXY(), r3.Circle(0.5).ToNurbsCurve())
    model.Objects.AddBrep(disk, attrs("disk"))
    scene = write(model, tmp_path / "disk.3dm")
    mesh = scene.mesh(scene.find("disk")[0], require_closed=False)
    v, f = mesh.vertices, mesh.faces
    np.testing.assert_allclose(np.hypot(v[:, 0], v[:, 1]), 0.5, rtol=1e-12)
    np.testing.assert_array_equal(v[:, 2], 0.0)
    area = 0.5 * np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1)
    assert area.sum() == pytest.approx(math.pi * 0.25, rel=0.01)  # inscribed 32-gon
    # a flat surface is told as flat (issue #36), not as a solid to close with Cap/Join
    with pytest.raises(
        GeometryError, match=r"disk .*: the brep is flat: its 32 vertices lie in one"
    ):
        scene.mesh(scene.find("disk")[0])


def test_inverted_and_inconsistent_meshes_are_oriented_outward(tmp_path: Path) -> None:
    model = new_model()
    model.Objects.AddMesh(box_mesh(HI, LO), attrs("inside_out"))  # mirrored: inward winding
    model.Objects.AddMesh(box_mesh(LO, HI, flip_one=True), attrs("one_face_flipped"))
    scene = write(model, tmp_path / "orient.3dm")
    for name in ("inside_out", "one_face_flipped"):
        mesh = scene.mesh(scene.find(name)[0])
        assert is_watertight(mesh), name
        assert volume(mesh) == pytest.approx(BOX_VOLUME, rel=1e-12), name


@pytest.mark.parametrize("with_scipy", [True, False])
def test_each_shell_of_a_multi_shell_mesh_is_oriented_outward(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, with_scipy: bool
) -> None:
    if not with_scipy:  # Rhino's Python may lack scipy: the union-find fallback
        monkeypatch.setitem(sys.modules, "scipy", None)
        monkeypatch.setitem(sys.modules, "scipy.sparse", None)
    m = box_mesh(LO, HI)
    inverted = box_mesh((3.0, 0.0, 0.0), (2.0, 1.0, 2.0))  # mirrored in x: inward winding
    for k in range(len(inverted.Vertices)):
        p = inverted.Vertices.Point3dAt(k)
        m.Vertices.AddPoint3d(p.X, p.Y, p.Z)
    for k in range(inverted.Faces.Count):
        a, b, c, d = (i + 24 for i in inverted.Faces[k])
        m.Faces.AddFace(a, b, c, d)
    model = new_model()
    model.Objects.AddMesh(m, attrs("two_blocks"))
    scene = write(model, tmp_path / "shells.3dm")
    mesh = scene.mesh(scene.find("two_blocks")[0])
    assert is_watertight(mesh)
    v, f = mesh.vertices, mesh.faces
    vol6 = np.einsum("ij,ij->i", v[f[:, 0]], np.cross(v[f[:, 1]], v[f[:, 2]]))
    right = v[f].mean(axis=1)[:, 0] > 1.5
    assert vol6[~right].sum() / 6 == pytest.approx(BOX_VOLUME, rel=1e-12)
    assert vol6[right].sum() / 6 == pytest.approx(2.0, rel=1e-12)


def test_open_mesh_and_non_solid_objects_are_rejected(tmp_path: Path) -> None:
    model = new_model()
    open_box = r3.Mesh()
    for x, y, z in [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1)]:
        open_box.Vertices.AddPoint3d(x, y, z)
    open_box.Faces.AddFace(0, 3, 2, 1)
    open_box.Faces.AddFace(0, 1, 4)
    model.Objects.AddMesh(open_box, attrs("open"))
    model.Objects.AddLine(P(0, 0, 0), P(1, 0, 0), attrs("axis"))
    scene = write(model, tmp_path / "open.3dm")
    with pytest.raises(GeometryError, match=r"open \(Default.*not a closed solid"):
        scene.mesh(scene.find("open")[0])
    mesh = scene.mesh(scene.find("open")[0], require_closed=False)
    assert mesh.n_triangles == 3
    with pytest.raises(GeometryError, match=r"axis.*a line is not a solid"):
        scene.mesh(scene.find("axis")[0])


# ---------------------------------------------------------------- reading


def layered_scene(tmp_path: Path) -> Tuple[Scene, str]:
    model = new_model()
    walls = model.Layers.AddLayer("Walls", (0, 0, 0, 255))
    sub = r3.Layer()
    sub.Name = "North"
    sub.ParentLayerId = model.Layers[walls].Id
    north = model.Layers.Add(sub)
    axes = model.Layers.AddLayer("Axes", (0, 0, 0, 255))
    site = model.Layers.AddLayer("Site", (0, 0, 0, 255))  # holds no object itself
    ties = r3.Layer()
    ties.Name = "Ties"
    ties.ParentLayerId = model.Layers[site].Id
    ties_index = model.Layers.Add(ties)
    gid = uuid.UUID("0123abcd-0000-4000-8000-00000000beef")
    a = attrs("wall", walls, density="1800")
    a.Id = gid
    brep = r3.Brep.CreateFromBox(box((0, 0, 0), (1, 1, 1)))
    brep.SetUserString("source", "survey")
    model.Objects.AddBrep(brep, a)
    model.Objects.AddBrep(r3.Brep.CreateFromBox(box((0, 2, 0), (1, 3, 1))), attrs("wall_n", north))
    model.Objects.AddLine(P(1, 0, 0), P(1, 1, 0), attrs("axis", axes))
    model.Objects.AddPolyline([P(0, 0, 0), P(0, 1, 0)], attrs("axis_back", axes))
    model.Objects.AddLine(P(0, 0, 2), P(1, 0, 2), attrs("tie", ties_index))
    return write(model, tmp_path / "layers.3dm"), str(gid)


def test_objects_carry_name_layer_path_kind_and_user_text(tmp_path: Path) -> None:
    scene, gid = layered_scene(tmp_path)
    wall = scene.find("wall")[0]
    assert isinstance(wall, SceneObject)
    assert (wall.id, wall.name, wall.layer, wall.kind) == (gid, "wall", "Walls", "brep")
    assert wall.user_text == {"density": "1800", "source": "survey"}
    assert wall.label() == "wall (Walls, 0123abcd)"
    assert scene.find("wall_n")[0].layer == "Walls::North"
    assert [o.kind for o in scene.find({"layer": "Axes"})] == ["line", "polyline"]
    assert scene.units == "meters" and scene.unit_scale == 1.0


def test_find_by_name_layer_with_sublayers_and_id(tmp_path: Path) -> None:
    scene, gid = layered_scene(tmp_path)
    names = lambda objs: [o.name for o in objs]  # noqa: E731
    assert names(scene.find({"name": "axis"})) == ["axis"]
    assert names(scene.find({"layer": "Walls"})) == ["wall", "wall_n"]
    assert names(scene.find({"layer": "Walls::North"})) == ["wall_n"]
    assert names(scene.find({"layer": "North"})) == ["wall_n"]
    assert names(scene.find({"layer": "Site"})) == ["tie"]
    assert names(scene.find({"layer": "Ties"})) == ["tie"]
    assert names(scene.find({"layer": "Site::Ties"})) == ["tie"]
    assert names(scene.find({"id": gid.upper()})) == ["wall"]
    assert names(scene.find({"id": "{" + gid + "}"})) == ["wall"]


def test_find_unknown_selector_names_it_and_lists_what_exists(tmp_path: Path) -> None:
    scene, _ = layered_scene(tmp_path)
    with pytest.raises(InputError) as err:
        scene.find("wal")
    msg = str(err.value)
    assert "'wal'" in msg and "'wall'" in msg and "'axis'" in msg
    with pytest.raises(InputError, match=r"'Roof'.*'Walls::North'"):
        scene.find({"layer": "Roof"})
    with pytest.raises(InputError, match="id"):
        scene.find({"id": str(uuid.UUID(int=1))})
    with pytest.raises(InputError, match="unknown selector key 'colour'"):
        scene.find({"colour": "red"})


def test_truncated_or_foreign_bytes_are_an_input_error(tmp_path: Path) -> None:
    scene, _ = layered_scene(tmp_path)
    data = (tmp_path / "layers.3dm").read_bytes()
    ok = Scene.from_bytes(data, "layers.3dm")
    assert [o.name for o in ok.objects] == [o.name for o in scene.objects]
    assert ok.path == "layers.3dm"
    for bad in (data[: len(data) // 2], data[:100], b"", b"solid cube\nendsolid\n"):
        with pytest.raises(InputError, match=r"scene: cannot read upload\.3dm as a \.3dm file"):
            Scene.from_bytes(bad)
    (tmp_path / "cut.3dm").write_bytes(data[:-64])
    with pytest.raises(InputError, match=r"cannot read .*cut.3dm"):
        Scene.from_3dm(tmp_path / "cut.3dm")
    with pytest.raises(InputError, match="file not found"):
        Scene.from_3dm(tmp_path / "missing.3dm")


# ---------------------------------------------------------------- lines and planes


def test_line_from_line_polyline_and_straight_curve(tmp_path: Path) -> None:
    model = new_model()
    model.Objects.AddLine(P(0.5, 0, 0), P(0.5, 1, 0), attrs("line"))
    model.Objects.AddPolyline([P(0, 0, 1), P(0, 2, 1)], attrs("poly2"))
    nurbs = r3.NurbsCurve.CreateControlPointCurve([P(0, 0, 2), P(1, 0, 2), P(3, 0, 2)], 1)
    model.Objects.AddCurve(nurbs, attrs("straight3"))
    model.Objects.AddPolyline([P(0, 0, 0), P(1, 0, 0), P(1, 1, 0)], attrs("bent"))
    model.Objects.AddPoint(P(0, 0, 0), attrs("pt"))
    scene = write(model, tmp_path / "lines.3dm")
    for name, a, b in [
        ("line", (0.5, 0, 0), (0.5, 1, 0)),
        ("poly2", (0, 0, 1), (0, 2, 1)),
        ("straight3", (0, 0, 2), (3, 0, 2)),
    ]:
        start, end = scene.line(scene.find(name)[0])
        np.testing.assert_array_equal(start, a)
        np.testing.assert_array_equal(end, b)
    with pytest.raises(GeometryError, match=r"bent.*not straight"):
        scene.line(scene.find("bent")[0])
    with pytest.raises(GeometryError, match=r"pt.*not a line"):
        scene.line(scene.find("pt")[0])


def test_plane_from_surface_curves_and_single_face_brep(tmp_path: Path) -> None:
    model = new_model()
    s2 = math.sqrt(0.5)
    diag = r3.Plane(P(0, 1, 8), r3.Vector3d(1, 0, 0), r3.Vector3d(0, s2, -s2))
    model.Objects.AddSurface(
        r3.PlaneSurface(diag, r3.Interval(-0.1, 0.7), r3.Interval(0, 7)), attrs("crack_srf")
    )
    model.Objects.AddPolyline([P(0, 6, 3), P(0, 2, 7), P(0.6, 6, 3)], attrs("crack_3pt"))
    model.Objects.AddPolyline(
        [P(0, 6, 3), P(0.6, 6, 3), P(0.6, 2, 7), P(0, 2, 7), P(0, 6, 3)], attrs("crack_loop")
    )
    circle = r3.Circle(0.5)
    circle.Plane = diag
    model.Objects.AddCircle(circle, attrs("crack_circle"))
    loop = r3.Polyline([P(0, 0, 0), P(1, 0, 0), P(1, 1, 0), P(0, 1, 0), P(0, 0, 0)])
    brep = r3.Brep.CreateTrimmedPlane(r3.Plane.WorldXY(), loop.ToPolylineCurve())
    model.Objects.AddBrep(brep, attrs("flat_brep"))
    model.Objects.AddPolyline([P(0, 0, 0), P(1, 0, 0), P(1, 1, 0), P(1, 1, 1)], attrs("twisted"))
    model.Objects.AddLine(P(0, 0, 0), P(1, 0, 0), attrs("line"))
    model.Objects.AddBrep(r3.Brep.CreateFromBox(box((0, 0, 0), (1, 1, 1))), attrs("cube"))
    scene = write(model, tmp_path / "planes.3dm")

    expected = np.array([0.0, s2, s2])
    for name in ("crack_srf", "crack_3pt", "crack_loop", "crack_circle"):
        point, normal = scene.plane(scene.find(name)[0])
        assert np.linalg.norm(normal) == pytest.approx(1.0, abs=1e-15)
        assert abs(float(normal @ expected)) == pytest.approx(1.0, abs=1e-12), name
        # every such plane contains the line y + z = 9 at any x
        assert float((point - [0, 1, 8]) @ expected) == pytest.approx(0.0, abs=1e-12), name
    # orientation: surface normal; right-hand rule along the points
    assert scene.plane(scene.find("crack_srf")[0])[1] @ expected > 0
    assert scene.plane(scene.find("crack_3pt")[0])[1] @ expected > 0
    point, normal = scene.plane(scene.find("flat_brep")[0])
    np.testing.assert_allclose(point, [0.5, 0.5, 0.0], atol=1e-15)
    np.testing.assert_allclose(np.abs(normal), [0, 0, 1], atol=1e-15)
    with pytest.raises(GeometryError, match=r"twisted.*not planar"):
        scene.plane(scene.find("twisted")[0])
    with pytest.raises(GeometryError, match=r"line.*does not define a plane"):
        scene.plane(scene.find("line")[0])
    with pytest.raises(GeometryError, match=r"cube.*6 faces"):
        scene.plane(scene.find("cube")[0])


# ---------------------------------------------------------------- triangulation


def tri_area2(pts: np.ndarray, tris: List[Tuple[int, int, int]]) -> np.ndarray:
    t = np.asarray(tris)
    a, b, c = pts[t[:, 0]], pts[t[:, 1]], pts[t[:, 2]]
    return (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])


def shoelace(p: np.ndarray) -> float:
    x, y = p[:, 0], p[:, 1]
    return 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y)))


def check_triangulation(outer: np.ndarray, holes: Sequence[np.ndarray]) -> None:
    tris = triangulate_polygon(outer, holes)
    pts = np.vstack([outer, *holes])
    a2 = tri_area2(pts, tris)
    assert np.all(a2 > 0.0), "every triangle counter-clockwise and non-degenerate"
    exact = shoelace(outer) - sum(shoelace(h) for h in holes)
    assert 0.5 * a2.sum() == pytest.approx(exact, rel=1e-12)
    assert len(tris) == len(pts) - 2 + 2 * len(holes)  # Euler: all vertices used


def test_triangulates_comb_with_collinear_vertices_either_orientation() -> None:
    comb = np.array(
        [
            [0, 0],
            [1, 0],
            [2, 0],
            [3, 0],
            [3, 3],
            [2.5, 3],
            [2.5, 1],
            [2, 1],
            [2, 3],
            [1, 3],
            [1, 1],
            [0.5, 1],
            [0.5, 3],
            [0, 3],
            [0, 2],
            [0, 1],
        ],
        float,
    )
    check_triangulation(comb, [])
    check_triangulation(comb[::-1].copy(), [])


def test_triangulates_polygon_with_several_holes() -> None:
    outer = np.array([[0, 0], [6, 0], [6, 3], [3, 4], [0, 3]], float)
    holes = [
        np.array([[0.5, 0.5], [1.5, 0.5], [1.5, 2.5], [0.5, 2.5]], float),
        np.array([[2, 1], [2.5, 2], [3, 1]], float),  # clockwise already
        np.array(
            [[4, 0.5], [5.5, 0.5], [5.5, 2.5], [5, 2.5], [5, 1], [4.5, 1], [4.5, 2.5], [4, 2.5]],
            float,
        ),
        np.array([[3, 2.5], [3.5, 2.5], [3.5, 3.2], [3, 3.2]], float),  # same x as hole 2
    ]
    check_triangulation(outer, holes)


def test_triangulation_rejects_self_intersecting_boundary() -> None:
    bowtie = np.array([[0, 0], [1, 1], [1, 0], [0, 1]], float)
    with pytest.raises(ValueError):
        triangulate_polygon(bowtie)


@settings(max_examples=60, deadline=None)
@given(
    radii=st.lists(st.floats(0.4, 1.0), min_size=3, max_size=40),
    hole=st.booleans(),
    scale=st.sampled_from([1e-3, 1.0, 1e3]),
)
def test_star_shaped_polygons_are_covered_exactly(
    radii: List[float], hole: bool, scale: float
) -> None:
    n = len(radii)
    t = 2 * np.pi * np.arange(n) / n
    outer = scale * np.column_stack([np.cos(t), np.sin(t)]) * np.asarray(radii)[:, None]
    holes: List[np.ndarray] = []
    if hole:
        s = 2 * np.pi * np.arange(7) / 7 + 0.3
        holes.append(scale * 0.2 * np.column_stack([np.cos(s), np.sin(s)]))
    check_triangulation(outer, holes)
