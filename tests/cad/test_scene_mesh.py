"""Scan meshes (PLY, OBJ, STL, OFF) as scenes, and the read_scene dispatcher.

Each test writes real files in a temporary folder: the scans with trimesh's exporters, the
same mesh as a ``.3dm`` with rhino3dm. A scan and the ``.3dm`` must give the same constants;
the mesh's coordinates are multiples of 1/8 mm, exact in float32 (PLY, STL) and in 8-digit
text (OBJ, OFF), so the files hold the same numbers.
"""

import json
from pathlib import Path
from typing import Any, Dict, List, Tuple

import numpy as np
import pytest

r3 = pytest.importorskip("rhino3dm")
trimesh = pytest.importorskip("trimesh")

from cad_maths.mechanisms.build import constants_from_spec  # noqa: E402
from cad_maths.scene_3dm import Scene  # noqa: E402
from cad_maths.scene_mesh import MeshScene  # noqa: E402
from cad_maths.scenes import read_scene  # noqa: E402
from shared_schema.errors import GeometryError, InputError  # noqa: E402
from shared_schema.spec import parse_spec  # noqa: E402

#: A wall 1.2 m long, 0.3 m thick, 2.5 m high, with a stepped relief on its front face [mm].
SIZE_MM = (1200.0, 300.0, 2500.0)

SPEC = {
    "mechanisms": [
        {
            "id": "S1",
            "typology": "single_block",
            "rocking": "two_sided",
            "groups": [{"objects": ["wall"], "density": 1900.0}],
            "axis": {"start": [0.0, 0.0, 0.0], "end": [1.2, 0.0, 0.0]},
            "cracks": [{"points": [[0.0, 0.0, 2.1], [1.0, 0.0, 2.3], [0.0, 1.0, 2.1]]}],
        }
    ]
}
KEYS = ("I0", "K", "Q", "p_eq", "lam", "phi_ov")


def scan_wall() -> Tuple[np.ndarray, np.ndarray]:
    """A closed, outward, relief-carved box mesh with vertices on a 1/8 mm grid [mm]."""
    box = trimesh.creation.box(extents=SIZE_MM)
    box.apply_translation(np.array(SIZE_MM) / 2)
    for _ in range(3):
        box = box.subdivide()
    v = np.array(box.vertices, dtype=np.float64)
    f = np.array(box.faces, dtype=np.int64)
    rng = np.random.default_rng(7)
    front = (v[:, 1] == 0.0) & (v[:, 0] > 0) & (v[:, 0] < SIZE_MM[0])
    front &= (v[:, 2] > 0) & (v[:, 2] < SIZE_MM[2])
    v[front, 1] = rng.integers(0, 160, front.sum()) / 8.0  # up to 20 mm deep, exact
    return v, f


def write_3dm(path: Path, v: np.ndarray, f: np.ndarray, units: Any, name: str = "wall") -> None:
    model = r3.File3dm()
    model.Settings.ModelUnitSystem = units
    mesh = r3.Mesh()
    for x, y, z in v.tolist():
        mesh.Vertices.Add(x, y, z)
    for a, b, c in f.tolist():
        mesh.Faces.AddFace(a, b, c)
    attr = r3.ObjectAttributes()
    attr.Name = name
    model.Objects.AddMesh(mesh, attr)
    assert model.Write(str(path), 8)


def constants(scene: Any, spec: Dict[str, Any] = SPEC) -> Dict[str, Any]:
    cf = constants_from_spec(
        parse_spec(json.dumps(spec), "scan.spec.json"),
        scene,
        scene_name=str(scene.path),
        spec_name="scan.spec.json",
    )
    (mech,) = json.loads(cf.model_dump_json(exclude_none=True))["mechanisms"]
    return mech  # type: ignore[no-any-return]


@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory) -> Dict[str, Path]:
    folder = tmp_path_factory.mktemp("scans")
    v, f = scan_wall()
    mesh = trimesh.Trimesh(v, f, process=False)
    out = {}
    for ext in ("ply", "obj", "stl", "off"):
        out[ext] = folder / f"wall.{ext}"
        mesh.export(out[ext])
    out["3dm"] = folder / "wall.3dm"
    write_3dm(out["3dm"], v, f, r3.UnitSystem.Millimeters)
    return out


def test_scan_files_hold_the_exact_mesh(files: Dict[str, Path]) -> None:
    v, _ = scan_wall()
    for ext in ("ply", "obj", "stl", "off"):
        loaded = trimesh.load_mesh(files[ext], process=False)
        got = np.unique(np.asarray(loaded.vertices, dtype=np.float64), axis=0)
        np.testing.assert_array_equal(got, np.unique(v, axis=0), err_msg=ext)


@pytest.mark.parametrize("ext", ["ply", "obj", "stl", "off"])
def test_scan_gives_the_constants_of_the_same_mesh_in_a_3dm(
    files: Dict[str, Path], ext: str
) -> None:
    ref = constants(read_scene(files["3dm"]))
    got = constants(read_scene(files[ext], units="mm"))
    assert got["provenance"]["scene_units"] == "millimeters"
    for side in ("positive", "negative"):
        if side not in ref:
            continue
        for k in KEYS:
            assert got[side][k] == pytest.approx(ref[side][k], rel=1e-12, abs=0), (side, k)
    assert got["eta"] == pytest.approx(ref["eta"], rel=1e-12)
    assert got["geometry"]["mass_kg"] == pytest.approx(ref["geometry"]["mass_kg"], rel=1e-12)
    # and the crack really cut the wall: less than the whole box's mass
    assert ref["geometry"]["mass_kg"] < 1900.0 * 1.2 * 0.3 * 2.5


def test_scan_units_scale_to_metres_exactly(files: Dict[str, Path]) -> None:
    raw = np.asarray(trimesh.load_mesh(files["ply"], process=False).vertices, np.float64)
    # exact ratios: 1 in = 254/10000 m, so 10000 in are exactly 254 m
    ratios = {"mm": (1, 1000), "cm": (1, 100), "m": (1, 1), "in": (254, 10000), "ft": (3048, 10000)}
    for units, (num, den) in ratios.items():
        scene = read_scene(files["ply"], units=units)
        got = scene.mesh(scene.find("wall")[0]).vertices
        assert scene.unit_scale == num / den
        # welding keeps first occurrences, so compare as sets of points
        want = np.unique(raw * num / den, axis=0)
        np.testing.assert_array_equal(np.unique(got, axis=0), want)


def test_scan_needs_units_and_names_the_field(files: Dict[str, Path]) -> None:
    with pytest.raises(
        InputError, match=r"wall\.ply: a \.ply file carries no length unit; give units"
    ) as exc:
        read_scene(files["ply"])
    assert exc.value.field == "units"
    with pytest.raises(InputError, match=r"unknown units 'furlong'") as exc:
        read_scene(files["obj"], units="furlong")
    assert exc.value.field == "units"


def test_3dm_units_may_be_repeated_not_contradicted(files: Dict[str, Path], tmp_path: Path) -> None:
    assert read_scene(files["3dm"], units="mm").units == "millimeters"
    with pytest.raises(InputError, match=r"wall\.3dm is in millimeters .* not meters") as exc:
        read_scene(files["3dm"], units="m")
    assert exc.value.field == "units"
    # a model saved without units takes the units it is given
    v, f = scan_wall()
    path = tmp_path / "unitless.3dm"
    write_3dm(
        path, v, f, r3.UnitSystem.None_ if hasattr(r3.UnitSystem, "None_") else r3.UnitSystem.Unset
    )
    plain = read_scene(path)
    assert plain.unit_scale == 1.0
    scaled = read_scene(path, units="mm")
    assert scaled.units == "millimeters"
    a = plain.mesh(plain.find("wall")[0]).vertices
    b = scaled.mesh(scaled.find("wall")[0]).vertices
    np.testing.assert_array_equal(b, a / 1e3)


def test_scan_from_bytes_is_read_like_the_file(files: Dict[str, Path]) -> None:
    data = files["ply"].read_bytes()
    scene = read_scene(data, name="upload.ply", units="mm")
    assert [o.name for o in scene.objects] == ["upload"]
    with pytest.raises(InputError, match="needs its file name"):
        read_scene(data)
    with pytest.raises(InputError, match=r"unknown scene format \.dwg; rockmech reads \.3dm"):
        read_scene(data, name="upload.dwg")
    with pytest.raises(InputError, match=r"junk\.ply is not a PLY file: a PLY file starts") as exc:
        read_scene(b"not a ply at all", name="junk.ply", units="mm")
    assert exc.value.field == "scene"


def test_a_scan_has_no_lines_or_planes_so_the_spec_must_give_points(
    files: Dict[str, Path],
) -> None:
    scene = read_scene(files["ply"], units="mm")
    by_object = json.loads(json.dumps(SPEC))
    by_object["mechanisms"][0]["axis"] = {"object": "wall"}
    with pytest.raises(GeometryError, match=r"a mesh is not a line; .* 'start' and 'end' points"):
        constants(scene, by_object)
    by_object["mechanisms"][0]["axis"] = {"object": "axis"}
    with pytest.raises(InputError, match=r"no object with name 'axis' .* 'start' and 'end'"):
        constants(scene, by_object)
    by_plane = json.loads(json.dumps(SPEC))
    by_plane["mechanisms"][0]["cracks"] = [{"object": "wall"}]
    with pytest.raises(GeometryError, match=r"does not define a plane; .* three 'points'"):
        constants(scene, by_plane)


OBJ_TWO = """# two tetrahedra
o {a}
v 0 0 0
v 1 0 0
v 0 1 0
v 0 0 1
f 1 3 2
f 1 2 4
f 1 4 3
f 2 3 4
o {b}
v 5 0 0
v 7 0 0
v 5 2 0
v 5 0 2
f 5 7 6
f 5 6 8
f 5 8 7
f 6 7 8
"""


def tet_volume_m3(edge_mm: float) -> float:
    return (edge_mm * 1e-3) ** 3 / 6


def test_obj_objects_are_selected_by_their_names(tmp_path: Path) -> None:
    path = tmp_path / "two.obj"
    path.write_text(OBJ_TWO.format(a="small", b="large"))
    scene = read_scene(path, units="mm")
    assert sorted(o.name for o in scene.objects) == ["large", "small"]
    for name, edge in (("small", 1.0), ("large", 2.0)):
        m = scene.mesh(scene.find(name)[0])
        vol = (
            np.einsum(
                "ij,ij->i",
                m.vertices[m.faces[:, 0]],
                np.cross(m.vertices[m.faces[:, 1]], m.vertices[m.faces[:, 2]]),
            ).sum()
            / 6
        )
        assert vol == pytest.approx(tet_volume_m3(edge), rel=1e-12)
        assert m.n_triangles == 4  # the other object's vertices are not carried along
    # groups name the meshes when there are no objects
    path.write_text(OBJ_TWO.format(a="small", b="large").replace("o ", "g "))
    assert sorted(o.name for o in read_scene(path, units="mm").objects) == ["large", "small"]


def test_repeated_obj_object_name_is_an_error_not_a_merge(tmp_path: Path) -> None:
    path = tmp_path / "twice.obj"
    path.write_text(OBJ_TWO.format(a="stone", b="stone"))
    scene = read_scene(path, units="mm")
    with pytest.raises(InputError, match=r"2 meshes are named 'stone' in twice\.obj"):
        scene.find("stone")


def test_open_scan_is_refused_naming_the_object(tmp_path: Path) -> None:
    v, f = scan_wall()
    path = tmp_path / "holed.ply"
    trimesh.Trimesh(v, f[:-3], process=False).export(path)
    scene = read_scene(path, units="mm")
    with pytest.raises(GeometryError, match=r"holed \(holed#0\): the mesh is not a closed solid"):
        scene.mesh(scene.find("holed")[0])


def test_duplicate_names_in_a_3dm_are_an_error_listing_ids(tmp_path: Path) -> None:
    v, f = scan_wall()
    path = tmp_path / "dup.3dm"
    model = r3.File3dm()
    model.Settings.ModelUnitSystem = r3.UnitSystem.Millimeters
    ids: List[str] = []
    for dx in (0.0, 2000.0):
        mesh = r3.Mesh()
        for x, y, z in v.tolist():
            mesh.Vertices.Add(x + dx, y, z)
        for a, b, c in f.tolist():
            mesh.Faces.AddFace(a, b, c)
        attr = r3.ObjectAttributes()
        attr.Name = "wall"
        ids.append(str(model.Objects.AddMesh(mesh, attr)))
    assert model.Write(str(path), 8)
    scene = Scene.from_3dm(path)
    with pytest.raises(InputError, match=r"2 objects are named 'wall' in dup\.3dm") as exc:
        constants(scene)
    for i in ids:
        assert i in str(exc.value)
    # selecting one by id works, and gives the single wall's constants
    by_id = json.loads(json.dumps(SPEC))
    by_id["mechanisms"][0]["groups"][0]["objects"] = [{"id": ids[0]}]
    single = constants(scene, by_id)
    ref = constants(
        MeshScene.from_bytes(
            trimesh.Trimesh(v, f, process=False).export(file_type="ply"), "wall.ply", units="mm"
        )
    )
    assert single["positive"]["p_eq"] == pytest.approx(ref["positive"]["p_eq"], rel=1e-12)


def test_cli_constants_reads_a_scan_with_units(files: Dict[str, Path], tmp_path: Path) -> None:
    from typer.testing import CliRunner

    from solver_service.cli import app

    spec = tmp_path / "scan.spec.json"
    spec.write_text(json.dumps(SPEC))
    runner = CliRunner()
    out = {}
    for ext, extra in (("3dm", []), ("ply", ["--units", "mm"]), ("obj", ["--units", "mm"])):
        out[ext] = tmp_path / f"{ext}.json"
        res = runner.invoke(
            app, ["constants", str(files[ext]), str(spec), "-o", str(out[ext]), *extra]
        )
        assert res.exit_code == 0, res.output
    ref = json.loads(out["3dm"].read_text())["mechanisms"][0]["positive"]
    for ext in ("ply", "obj"):
        got = json.loads(out[ext].read_text())["mechanisms"][0]["positive"]
        for k in KEYS:
            assert got[k] == pytest.approx(ref[k], rel=1e-12), (ext, k)
    res = runner.invoke(app, ["constants", str(files["ply"]), str(spec), "-o", str(out["ply"])])
    assert res.exit_code == 2
    assert "units: wall.ply: a .ply file carries no length unit; give units" in res.output
    assert "Traceback" not in res.output
