"""The .3dm layout check: real files pass, a corrupt length anywhere it walks is refused fast.

The corrupt copies are made from the bundled scenes by a walk written here from the openNURBS
header (``opennurbs_3dm.h``), independent of the module's: every chunk inside a table, an
object or layer record, or a class chunk gets its length set to 2^63 - 1, or to one byte
past its parent.
"""

from __future__ import annotations

import struct
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from typer.testing import CliRunner

from cad_maths.archive_3dm import check_3dm, crc_problem, layout_problem
from cad_maths.scene_3dm import Scene
from shared_schema.errors import InputError
from solver_service.cli import app

REPO = Path(__file__).resolve().parents[2]
SCENES = REPO / "examples" / "scenes"
#: Every .3dm file of the repository and of the shared folder beside it (if any).
ALL_3DM = sorted(
    p
    for root in (REPO / "examples", REPO / "tests", REPO.parent / "shared")
    if root.is_dir()
    for p in root.rglob("*.3dm")
)
#: Chunks whose content this walk follows: tables (top level), object and layer records,
#: the openNURBS class chunk (opennurbs_3dm.h).
OBJECT_RECORD, LAYER_RECORD, CLASS = 0x20008070, 0x20008050, 0x00027FFA


def _chunks(data: bytes) -> Iterator[tuple[int, int, int, int]]:
    """(offset of the length field, parent end, depth, code) of the chunks walked (V5+)."""
    todo = [(32, len(data), 0)]
    while todo:
        pos, end, depth = todo.pop()
        while pos < end:
            code, length = struct.unpack_from("<IQ", data, pos)
            if depth:
                yield pos + 4, end, depth, code
            pos += 12
            if code & 0x80000000:
                continue
            inner = length - 4 if code & 0x8000 else length
            if (depth == 0 and code & 0x10000000) or code in (OBJECT_RECORD, LAYER_RECORD, CLASS):
                todo.append((pos, pos + inner, depth + 1))
            pos += length


def test_every_3dm_file_of_the_repository_passes() -> None:
    assert len(ALL_3DM) >= 8
    for path in ALL_3DM:
        assert layout_problem(path.read_bytes()) is None, path


def test_rhino3dm_written_files_of_every_version_pass(tmp_path: Path) -> None:
    rhino3dm = pytest.importorskip("rhino3dm")
    model = rhino3dm.File3dm()
    for i in range(2):
        material = rhino3dm.Material()
        material.Name = f"m{i}"
        model.Materials.Add(material)
        layer = rhino3dm.Layer()
        layer.Name = f"layer{i}"
        model.Layers.Add(layer)
    group = rhino3dm.Group()
    group.Name = "g"
    model.Groups.Add(group)
    model.Linetypes.Add(rhino3dm.Linetype.Border)
    model.DimStyles.Add(rhino3dm.DimensionStyle())
    attributes = rhino3dm.ObjectAttributes()
    attributes.SetUserString("role", "wall")
    model.Objects.AddPoint(rhino3dm.Point3d(1, 2, 3), attributes)
    model.Objects.AddSphere(rhino3dm.Sphere(rhino3dm.Point3d(0, 0, 0), 2))
    point = rhino3dm.Point(rhino3dm.Point3d(0, 0, 0))
    origin = rhino3dm.Point3d(0, 0, 0)
    model.InstanceDefinitions.Add("b", "", "", "", origin, (point,), (attributes,))
    # Objects whose data nests other chunks (a Brep's curves and surfaces, user data on the
    # geometry itself), so the CRC check's search for nested chunks is exercised too.
    brep = rhino3dm.Brep.CreateFromBox(rhino3dm.Box(rhino3dm.BoundingBox(0, 0, 0, 1, 2, 3)))
    brep.SetUserString("density_kg_m3", "1800")
    model.Objects.AddBrep(brep, attributes)
    mesh = rhino3dm.Mesh()
    for x, y in ((0, 0), (1, 0), (1, 1), (0, 1)):
        mesh.Vertices.Add(x, y, 0)
    mesh.Faces.AddFace(0, 1, 2, 3)
    mesh.SetUserString("role", "floor")
    model.Objects.AddMesh(mesh)
    circle = rhino3dm.Circle(rhino3dm.Point3d(0, 0, 0), 1).ToNurbsCurve()
    model.Objects.AddExtrusion(rhino3dm.Extrusion.Create(circle, 5, True))
    cloud = rhino3dm.PointCloud()
    for i in range(300):
        cloud.Add(rhino3dm.Point3d(i, 2 * i, 3 * i))
    model.Objects.AddPointCloud(cloud)
    for version in (5, 6, 7, 8):
        path = tmp_path / f"v{version}.3dm"
        assert model.Write(str(path), version)
        assert layout_problem(path.read_bytes()) is None, version  # the CRCs included
        assert crc_problem(path.read_bytes()) is None, version


def _corrupt_copies(path: Path) -> Iterator[tuple[str, bytes]]:
    data = path.read_bytes()
    for at, end, depth, code in _chunks(data):
        if code & 0x80000000:
            continue
        for label, value in (("2^63-1", 2**63 - 1), ("one past", end - (at + 8) + 1)):
            bad = bytearray(data)
            struct.pack_into("<Q", bad, at, value)
            yield f"{path.name} depth {depth} code {code:#x} at {at} {label}", bytes(bad)


@pytest.mark.parametrize("name", ["rect_wall.3dm", "portal_frame.3dm", "statue_column.3dm"])
def test_a_corrupt_length_inside_a_record_is_refused_in_milliseconds(name: str) -> None:
    copies = list(_corrupt_copies(SCENES / name))
    depths = {label.split(" depth ")[1].split()[0] for label, _ in copies}
    assert {"1", "2", "3"} <= depths  # records, class chunks and their contents are corrupted
    start = time.perf_counter()
    for label, bad in copies:
        assert layout_problem(bad) is not None, label
    per_file = (time.perf_counter() - start) / len(copies)
    assert per_file < 0.05, per_file


def test_the_scene_reader_refuses_a_corrupt_record_before_rhino3dm(tmp_path: Path) -> None:
    # The object record's own length, 2^63 - 1: rhino3dm read this from memory for 49 s.
    data = (SCENES / "rect_wall.3dm").read_bytes()
    at = next(a for a, _, _, code in _chunks(data) if code == OBJECT_RECORD)
    bad = bytearray(data)
    struct.pack_into("<Q", bad, at, 2**63 - 1)
    path = tmp_path / "corrupt.3dm"
    path.write_bytes(bytes(bad))
    message = f"cannot read {path} as a .3dm file (truncated, corrupt or not a Rhino model)"
    start = time.perf_counter()
    with pytest.raises(InputError, match="truncated, corrupt") as exc:
        Scene.from_3dm(path)
    assert message in str(exc.value)
    with pytest.raises(InputError, match=r"upload\.3dm"):
        Scene.from_bytes(bytes(bad))
    with pytest.raises(InputError, match=r"corrupt\.3dm"):
        check_3dm(bytes(bad), "corrupt.3dm")
    assert time.perf_counter() - start < 1.0


def test_rockmech_constants_refuses_a_corrupt_record_quickly(tmp_path: Path) -> None:
    data = (SCENES / "rect_wall.3dm").read_bytes()
    at = next(a for a, _, _, code in _chunks(data) if code == CLASS)
    bad = bytearray(data)
    struct.pack_into("<Q", bad, at, 2**63 - 1)
    (tmp_path / "corrupt.3dm").write_bytes(bytes(bad))
    spec = REPO / "examples" / "specs" / "rect_wall.spec.json"
    start = time.perf_counter()
    res = CliRunner().invoke(
        app,
        ["constants", str(tmp_path / "corrupt.3dm"), str(spec), "-o", str(tmp_path / "c.json")],
    )
    assert time.perf_counter() - start < 5.0
    assert res.exit_code == 2, res.output
    assert "as a .3dm file (truncated, corrupt or not a Rhino model)" in res.stderr
    assert res.stderr.count("\n") == 1
    assert not (tmp_path / "c.json").exists()


def _class_data(data: bytes) -> list[tuple[int, int]]:
    """(content start, end) of every object's class data chunk (``TCODE_OPENNURBS_CLASS_DATA``)."""
    out = []
    todo = [(32, len(data))]
    while todo:
        pos, end = todo.pop()
        chunks = []
        while pos + 12 <= end:
            code, length = struct.unpack_from("<IQ", data, pos)
            pos += 12
            if code & 0x80000000:
                continue
            if length > end - pos:
                break
            chunks.append((code, pos, pos + length))
            pos += length
        if pos != end:
            continue  # not a sequence of chunks: raw data
        for code, lo, hi in chunks:
            if code == 0x0002FFFC:
                out.append((lo, hi))
            else:
                todo.append((lo, hi - 4 if code & 0x8000 else hi))
    return out


@pytest.mark.parametrize("name", sorted(p.name for p in SCENES.glob("*.3dm")))
def test_a_flipped_bit_in_any_object_data_fails_the_crc_check(name: str) -> None:
    data = (SCENES / name).read_bytes()
    assert crc_problem(data) is None
    regions = sorted(_class_data(data), key=lambda r: r[1] - r[0])[-4:]  # the largest
    assert regions
    flipped = 0
    for lo, hi in regions:
        for offset in range(lo, hi, max(1, (hi - lo) // 6))[1:]:
            bad = bytearray(data)
            bad[offset] ^= 0x04
            problem = layout_problem(bytes(bad))
            # A flip in a nested chunk's type code is not covered by a CRC (rhino3dm then
            # refuses the chunk at once); everything else is.
            code_bytes = _nested_code_bytes(data, lo, hi)
            if offset in code_bytes:
                continue
            assert problem is not None and "fails its CRC check" in problem, (name, offset)
            flipped += 1
    assert flipped >= 8


def _nested_code_bytes(data: bytes, lo: int, hi: int) -> set[int]:
    """Offsets of the type codes of the anonymous chunks nested in [lo, hi)."""
    out: set[int] = set()
    at = data.find(b"\x00\x80\x00\x40", lo, hi)
    while at >= 0:
        out.update(range(at, at + 4))
        at = data.find(b"\x00\x80\x00\x40", at + 1, hi)
    return out
