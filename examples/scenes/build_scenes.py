"""Build the example ``.3dm`` scenes, in metres, deterministically.

Run ``python examples/scenes/build_scenes.py [OUT_DIR]`` (default: this folder). The object
names, layers and ids are fixed (ids are UUID5 of ``scene/name``), so spec files can refer to
them; README.md in this folder lists them. Only the file time stamps change between runs.

Solids use several rhino3dm kinds on purpose (Brep, Extrusion, Mesh), so each reading path of
``cad_maths.scene_3dm`` is exercised by the examples.

One example is a scan mesh instead: ``scan_wall.ply`` (binary PLY, in millimetres), a coarser
mesh of the ``scan_wall.3dm`` wall, for ``rockmech constants ... --units mm``.
"""

import math
import sys
import uuid
from pathlib import Path
from typing import Callable, Dict, List, Sequence, Tuple

import numpy as np

HERE = Path(__file__).resolve().parent
# UUID5 namespace of the example objects and layers.
NAMESPACE = uuid.UUID("6f1c2a52-0d0e-4c8b-9a57-3d1e2b7a9c40")
# Model absolute tolerance written into the files [m].
TOLERANCE = 1e-4
# Unit weights written as user text [kg/m^3] (spec files may override them).
DENSITY = {"brick": 1800.0, "stone": 2600.0, "bronze": 8500.0, "concrete": 2400.0}

Point = Tuple[float, float, float]


class Builder:
    """One scene under construction: layers, named objects, deterministic ids."""

    def __init__(self, scene: str) -> None:
        import rhino3dm

        self.r3 = rhino3dm
        self.scene = scene
        self.model = rhino3dm.File3dm()
        self.model.Settings.ModelUnitSystem = rhino3dm.UnitSystem.Meters
        self.model.Settings.ModelAbsoluteTolerance = TOLERANCE
        self.layers: Dict[str, int] = {}

    def _id(self, kind: str, name: str) -> uuid.UUID:
        return uuid.uuid5(NAMESPACE, f"{self.scene}/{kind}/{name}")

    def layer(self, name: str) -> int:
        """Return the index of a top-level layer, adding it on first use."""
        if name not in self.layers:
            layer = self.r3.Layer()
            layer.Name = name
            layer.Id = self._id("layer", name)
            self.layers[name] = self.model.Layers.Add(layer)
        return self.layers[name]

    def attrs(self, name: str, layer: str, material: str = "") -> object:
        """Return object attributes: name, fixed id, layer, material user text."""
        a = self.r3.ObjectAttributes()
        a.Name = name
        a.Id = self._id("object", name)
        a.LayerIndex = self.layer(layer)
        if material:
            a.SetUserString("material", material)
            a.SetUserString("density_kg_m3", f"{DENSITY[material]:g}")
        return a

    def box(self, name: str, layer: str, lo: Point, hi: Point, material: str) -> None:
        """Add a Brep box (six planar faces)."""
        bbox = self.r3.BoundingBox(*lo, *hi)
        brep = self.r3.Brep.CreateFromBox(self.r3.Box(bbox))
        self.model.Objects.AddBrep(brep, self.attrs(name, layer, material))

    def prism_y(
        self,
        name: str,
        layer: str,
        profile: Sequence[Tuple[float, float]],
        y0: float,
        y1: float,
        material: str,
    ) -> None:
        """Add an Extrusion along y of a closed x-z profile [(x, z), ...], from y0 to y1."""
        r3 = self.r3
        pts = [r3.Point3d(x, z, 0.0) for x, z in profile]
        curve = r3.Polyline([*pts, pts[0]]).ToPolylineCurve()
        ext = r3.Extrusion()
        # path towards -y with z up maps profile (x, y) to world (x, z)
        ok = ext.SetOuterProfile(curve, True) and ext.SetPathAndUp(
            r3.Point3d(0.0, y1, 0.0), r3.Point3d(0.0, y0, 0.0), r3.Vector3d(0.0, 0.0, 1.0)
        )
        _check_box(
            ext,
            ok,
            name,
            (min(x for x, _ in profile), y0, min(z for _, z in profile)),
            (max(x for x, _ in profile), y1, max(z for _, z in profile)),
        )
        self.model.Objects.AddExtrusion(ext, self.attrs(name, layer, material))

    def prism_z(
        self,
        name: str,
        layer: str,
        profile: Sequence[Tuple[float, float]],
        z0: float,
        z1: float,
        material: str,
    ) -> None:
        """Add an Extrusion along z of a closed x-y profile [(x, y), ...], from z0 to z1."""
        r3 = self.r3
        pts = [r3.Point3d(x, y, 0.0) for x, y in profile]
        curve = r3.Polyline([*pts, pts[0]]).ToPolylineCurve()
        ext = r3.Extrusion()
        # path towards +z with y up maps profile (x, y) to world (x, y)
        ok = ext.SetOuterProfile(curve, True) and ext.SetPathAndUp(
            r3.Point3d(0.0, 0.0, z0), r3.Point3d(0.0, 0.0, z1), r3.Vector3d(0.0, 1.0, 0.0)
        )
        xs, ys = [p[0] for p in profile], [p[1] for p in profile]
        _check_box(ext, ok, name, (min(xs), min(ys), z0), (max(xs), max(ys), z1))
        self.model.Objects.AddExtrusion(ext, self.attrs(name, layer, material))

    def mesh(self, name: str, layer: str, v: np.ndarray, f: np.ndarray, material: str) -> None:
        """Add a Mesh with double-precision vertices (AddPoint3d, not the float32 Add)."""
        _check_closed(v, f, name)
        m = self.r3.Mesh()
        add_v, add_f = m.Vertices.AddPoint3d, m.Faces.AddFace
        for x, y, z in v.tolist():
            add_v(x, y, z)
        for a, b, c in f.tolist():
            add_f(a, b, c)
        self.model.Objects.AddMesh(m, self.attrs(name, layer, material))

    def line(self, name: str, layer: str, a: Point, b: Point) -> None:
        """Add a line from a to b [m]."""
        r3 = self.r3
        self.model.Objects.AddLine(r3.Point3d(*a), r3.Point3d(*b), self.attrs(name, layer))

    def plane_surface(
        self,
        name: str,
        layer: str,
        origin: Point,
        xdir: Point,
        ydir: Point,
        xs: Tuple[float, float],
        ys: Tuple[float, float],
    ) -> None:
        """Add a planar surface on a plane (origin, x and y directions) over given extents."""
        r3 = self.r3
        plane = r3.Plane(r3.Point3d(*origin), r3.Vector3d(*xdir), r3.Vector3d(*ydir))
        srf = r3.PlaneSurface(plane, r3.Interval(*xs), r3.Interval(*ys))
        self.model.Objects.AddSurface(srf, self.attrs(name, layer))

    def write(self, path: Path) -> Path:
        """Write the model (Rhino 8 format)."""
        if not self.model.Write(str(path), 8):
            raise OSError(f"rhino3dm could not write {path}")
        return path


def _check_box(ext: object, ok: bool, name: str, lo: Point, hi: Point) -> None:
    bb = ext.GetBoundingBox()  # type: ignore[attr-defined]
    got = (bb.Min.X, bb.Min.Y, bb.Min.Z, bb.Max.X, bb.Max.Y, bb.Max.Z)
    if not ok or not np.allclose(got, (*lo, *hi), atol=1e-12):
        raise RuntimeError(f"{name}: extrusion came out at {got}, expected {(*lo, *hi)}")


def _check_closed(v: np.ndarray, f: np.ndarray, name: str) -> None:
    """Raise unless the mesh is closed, consistently oriented and of positive volume."""
    e = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    _, n_dir = np.unique(e, axis=0, return_counts=True)
    _, n_und = np.unique(np.sort(e, axis=1), axis=0, return_counts=True)
    vol = np.einsum("ij,ij->i", v[f[:, 0]], np.cross(v[f[:, 1]], v[f[:, 2]])).sum() / 6.0
    if not (np.all(n_dir == 1) and np.all(n_und == 2) and vol > 0.0):
        raise RuntimeError(f"{name}: the generated mesh is not a closed, outward solid")


# ---------------------------------------------------------------------- meshes


def ring_solid(
    rings: Sequence[Tuple[float, float, float, float, float, float]], n: int
) -> Tuple[np.ndarray, np.ndarray]:
    """Return a closed mesh through horizontal elliptic rings, capped at both ends.

    Parameters
    ----------
    rings : sequence of (z, cx, cy, rx, ry, twist)
        Ring height, centre, semi-axes [m] and angular offset [rad], bottom to top.
    n : int
        Vertices per ring.
    """
    t = 2.0 * np.pi * np.arange(n) / n
    z, cx, cy = rings[0][:3]
    v = [np.array([[cx, cy, z]])]
    for z, cx, cy, rx, ry, tw in rings:
        v.append(
            np.column_stack([cx + rx * np.cos(t + tw), cy + ry * np.sin(t + tw), np.full(n, z)])
        )
    z, cx, cy = rings[-1][:3]
    v.append(np.array([[cx, cy, z]]))
    verts = np.vstack(v)
    k = np.arange(n)
    k1 = (k + 1) % n
    faces = [np.column_stack([np.zeros(n, int), 1 + k1, 1 + k])]  # bottom, facing down
    for j in range(len(rings) - 1):
        a, b = 1 + j * n, 1 + (j + 1) * n
        faces.append(np.column_stack([a + k, a + k1, b + k1]))
        faces.append(np.column_stack([a + k, b + k1, b + k]))
    top, last = verts.shape[0] - 1, 1 + (len(rings) - 1) * n
    faces.append(np.column_stack([np.full(n, top), last + k, last + k1]))
    return verts, np.vstack(faces).astype(np.int64)


def grid_box_solid(
    size: Point, counts: Tuple[int, int, int], displace: Callable[[np.ndarray], np.ndarray]
) -> Tuple[np.ndarray, np.ndarray]:
    """Return a closed structured mesh of the box [0, sx] x [0, sy] x [0, sz], displaced.

    Each face is a grid of ``counts`` cells along its two axes; the faces are generated
    separately and welded where their vertices coincide (same integer grid index).
    ``displace(p)`` maps an (n, 3) array of box points to their final position.
    """
    n = np.asarray(counts)
    faces_v, faces_f, offset = [], [], 0
    # (axis, side): the face of normal +/- axis; u, v span it with u x v = outward normal
    for axis in range(3):
        u_ax, v_ax = (axis + 1) % 3, (axis + 2) % 3
        for side in (0, 1):
            iu, iv = np.meshgrid(np.arange(n[u_ax] + 1), np.arange(n[v_ax] + 1), indexing="ij")
            idx = np.zeros((*iu.shape, 3), dtype=np.int64)
            idx[..., axis] = side * n[axis]
            idx[..., u_ax], idx[..., v_ax] = iu, iv
            faces_v.append(idx.reshape(-1, 3))
            nv = n[v_ax] + 1
            a = (iu[:-1, :-1] * nv + iv[:-1, :-1]).ravel() + offset
            b, c, d = a + nv, a + nv + 1, a + 1
            tri = (
                np.column_stack([a, b, c, a, c, d])
                if side == 1
                else np.column_stack([a, c, b, a, d, c])
            ).reshape(-1, 3)
            faces_f.append(tri)
            offset += idx.shape[0] * idx.shape[1]
    keys = np.vstack(faces_v)
    uniq, inverse = np.unique(keys, axis=0, return_inverse=True)
    f = inverse.reshape(-1)[np.vstack(faces_f)]
    p = uniq / n * np.asarray(size, dtype=np.float64)
    return displace(p), f.astype(np.int64)


def slab_solid(
    origin: Point,
    e_s: Point,
    e_n: Point,
    thickness: float,
    outer: Sequence[Tuple[float, float]],
    holes: Sequence[Sequence[Tuple[float, float]]] = (),
) -> Tuple[np.ndarray, np.ndarray]:
    """Return a closed mesh of a wall: an elevation (s, z) with holes, extruded through n.

    The elevation lies in the plane through ``origin`` spanned by ``e_s`` and z; the wall
    fills ``0 <= n <= thickness`` along ``e_n``. Openings are through-holes.
    """
    # rockmech's own triangulation (exact vertices); the examples need the package anyway
    from cad_maths.geometry.polygon import orient_rings, triangulate_polygon

    o, es, en = (np.asarray(v, dtype=np.float64) for v in (origin, e_s, e_n))
    ez = np.array([0.0, 0.0, 1.0])
    rings = [np.asarray(outer, dtype=np.float64)] + [np.asarray(h, dtype=np.float64) for h in holes]
    # outer counter-clockwise, holes clockwise in (s, z): material on the left of each edge
    fixed = orient_rings(rings)
    pts2 = np.vstack(fixed)
    n = len(pts2)
    front = o + pts2[:, :1] * es + pts2[:, 1:] * ez
    verts = np.vstack([front, front + thickness * en])
    tris = np.array(triangulate_polygon(fixed[0], fixed[1:]), dtype=np.int64)
    # the triangles are counter-clockwise in (s, z): their normal is es x ez
    sign = float(np.dot(np.cross(es, ez), en))
    front_f = tris[:, ::-1] if sign > 0.0 else tris  # front faces look along -en
    faces = [front_f, (tris if sign > 0.0 else tris[:, ::-1]) + n]
    start = 0
    for r in fixed:
        k = np.arange(len(r)) + start
        k1 = np.roll(k, -1)
        start += len(r)
        quads = np.column_stack([k, k1, k1 + n, k, k1 + n, k + n]).reshape(-1, 3)
        # outward is to the right of each edge; flip the quads to face it
        d = pts2[k1 - 0] - pts2[k]
        right = d[:, 1:] * es - d[:, :1] * ez
        tri0 = verts[quads[0::2]]
        nrm = np.cross(tri0[:, 1] - tri0[:, 0], tri0[:, 2] - tri0[:, 0])
        flip = np.einsum("ij,ij->i", nrm, right) < 0.0
        quads = quads.reshape(-1, 2, 3)
        quads[flip] = quads[flip][:, :, ::-1]
        faces.append(quads.reshape(-1, 3))
    return verts, np.vstack(faces)


# ---------------------------------------------------------------------- scenes


def rect_wall(out: Path) -> Path:
    b = Builder("rect_wall")
    b.box("wall", "Walls", (0.0, 0.0, 0.0), (0.5, 1.0, 3.0), "brick")
    b.line("axis", "Axes", (0.5, 0.0, 0.0), (0.5, 1.0, 0.0))
    b.line("axis_back", "Axes", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0))
    return b.write(out / "rect_wall.3dm")


# Column: 24-sided prism, vertices on a circle of this radius [m].
COLUMN_R, COLUMN_H, COLUMN_SIDES = 0.3, 3.0, 24


def statue_column(out: Path) -> Path:
    b = Builder("statue_column")
    # vertices at half-step angles, so one edge faces +x and one -x
    t = 2.0 * np.pi * (np.arange(COLUMN_SIDES) + 0.5) / COLUMN_SIDES
    profile = list(zip((COLUMN_R * np.cos(t)).tolist(), (COLUMN_R * np.sin(t)).tolist()))
    b.prism_z("column", "Stone", profile, 0.0, COLUMN_H, "stone")
    # bronze figure leaning towards +x: plinth, legs, torso, shoulders, neck, head
    z0 = COLUMN_H
    rings = [
        (z0 + 0.00, 0.00, 0.00, 0.22, 0.20, 0.0),
        (z0 + 0.10, 0.00, 0.00, 0.22, 0.20, 0.0),
        (z0 + 0.12, 0.02, 0.01, 0.14, 0.10, 0.2),
        (z0 + 0.70, 0.05, 0.02, 0.12, 0.09, 0.3),
        (z0 + 0.76, 0.07, 0.02, 0.17, 0.11, 0.3),
        (z0 + 1.12, 0.11, 0.03, 0.20, 0.12, 0.4),
        (z0 + 1.18, 0.13, 0.03, 0.06, 0.05, 0.4),
        (z0 + 1.24, 0.14, 0.03, 0.06, 0.05, 0.4),
        (z0 + 1.28, 0.15, 0.02, 0.09, 0.09, 0.5),
        (z0 + 1.44, 0.16, 0.02, 0.09, 0.08, 0.5),
        (z0 + 1.50, 0.16, 0.02, 0.04, 0.04, 0.5),
    ]
    v, f = ring_solid(rings, 12)
    b.mesh("statue", "Bronze", v, f, "bronze")
    a = COLUMN_R * math.cos(math.pi / COLUMN_SIDES)  # apothem: the edge facing +x
    b.line("axis", "Axes", (a, -COLUMN_R, 0.0), (a, COLUMN_R, 0.0))
    b.line("axis_back", "Axes", (-a, -COLUMN_R, 0.0), (-a, COLUMN_R, 0.0))
    return b.write(out / "statue_column.3dm")


def facade(out: Path) -> Path:
    b = Builder("facade")
    # façade x in [0, 0.6] (outer face x = 0), y in [0, 6], z in [0, 8]; a pocket in the
    # inner face, x in [0.25, 0.6], z in [3.5, 3.8], carries the first floor
    b.prism_y(
        "facade",
        "Walls",
        [
            (0.0, 0.0),
            (0.6, 0.0),
            (0.6, 3.5),
            (0.25, 3.5),
            (0.25, 3.8),
            (0.6, 3.8),
            (0.6, 8.0),
            (0.0, 8.0),
        ],
        0.0,
        6.0,
        "brick",
    )
    b.box("side_wall_left", "Walls", (0.6, 0.0, 0.0), (5.6, 0.6, 8.0), "brick")
    b.box("side_wall_right", "Walls", (0.6, 5.4, 0.0), (5.6, 6.0, 8.0), "brick")
    b.box("back_wall", "Walls", (5.6, 0.0, 0.0), (6.2, 6.0, 8.0), "brick")
    # bears on the pocket floor (z = 3.5) over x in [0.3, 0.6]; clear of its back and top
    b.box("floor_bearing", "Floors", (0.3, 0.6, 3.5), (5.6, 5.4, 3.7), "concrete")
    # touches the façade's inner face (x = 0.6) only
    b.prism_y(
        "floor_abutting",
        "Floors",
        [(0.6, 6.5), (5.6, 6.5), (5.6, 6.7), (0.6, 6.7)],
        0.6,
        5.4,
        "concrete",
    )
    b.prism_y("roof", "Roof", [(0.0, 8.0), (6.2, 8.0), (3.1, 9.6)], 0.0, 6.0, "brick")
    # segmental barrel vault spanning façade -> back wall, springing at z = 4.0, rise 1.6 m,
    # 0.3 m thick measured vertically; 16 straight segments
    n_seg, span, rise, thick, z_s = 16, 5.0, 1.6, 0.3, 4.0
    radius = (span**2 / 4.0 + rise**2) / (2.0 * rise)
    xs = 0.6 + span * np.arange(n_seg + 1) / n_seg
    zi = z_s + rise - radius + np.sqrt(radius**2 - (xs - 0.6 - span / 2.0) ** 2)
    zi[0] = zi[-1] = z_s
    intrados = list(zip(xs.tolist(), zi.tolist()))
    extrados = [(x, z + thick) for x, z in intrados]
    b.prism_y("vault", "Vaults", intrados[::-1] + extrados, 0.6, 5.4, "brick")
    for name, y in (("tie_1", 2.0), ("tie_2", 4.0)):
        b.line(name, "Ties", (0.0, y, 7.8), (6.2, y, 7.8))
    # diagonal crack across the façade: contains x, falls 45 deg from (y 1, z 8) to (y 6, z 3)
    s = math.sqrt(0.5)
    b.plane_surface(
        "crack", "Cracks", (-0.1, 1.0, 8.0), (1.0, 0.0, 0.0), (0.0, s, -s), (0.0, 0.8), (-0.5, 7.6)
    )
    b.line("axis", "Axes", (0.0, 0.0, 0.0), (0.0, 6.0, 0.0))
    return b.write(out / "facade.3dm")


# Scan wall: cells across thickness, length, height (>= 200k triangles in all).
SCAN_SIZE, SCAN_CELLS = (0.6, 4.0, 5.0), (1, 200, 250)
# Amplitude of the smooth surface relief of each large face [m].
SCAN_RELIEF = 0.015


def _relief(y: np.ndarray, z: np.ndarray, phase: float) -> np.ndarray:
    """Smooth relief [m] of a large face: zero at the base so its bottom edges stay straight."""
    w = np.clip(z / 0.5, 0.0, 1.0)
    w = w * w * (3.0 - 2.0 * w)
    s = (
        0.5 * np.sin(2.1 * y + 1.3 * z + phase)
        + 0.3 * np.sin(5.3 * y - 3.7 * z + 2 * phase)
        + 0.2 * np.sin(11.0 * y + 9.0 * z + 3 * phase) * np.cos(7.0 * z - phase)
    )
    return SCAN_RELIEF * w * s


# The same wall as a small scan file: 5 times coarser along y and z, so its vertices are
# vertices of scan_wall.3dm's mesh (8,360 triangles, about 0.2 MB).
SCAN_PLY_CELLS = (1, 40, 50)
# Millimetres per metre: the PLY is in mm, as scans usually are.
MM_PER_M = 1000.0


def scan_wall_vertices(counts: Tuple[int, int, int]) -> Tuple[np.ndarray, np.ndarray]:
    """Return the scan wall's closed mesh with ``counts`` cells (x, y, z): vertices [m], faces.

    Both large faces carry :func:`_relief` (a different phase on each), blended linearly
    through the thickness.
    """
    t = SCAN_SIZE[0]

    def displace(p: np.ndarray) -> np.ndarray:
        q = p.copy()
        s = p[:, 0] / t  # 0 on the outer face (x = 0), 1 on the inner face
        q[:, 0] += (1.0 - s) * _relief(p[:, 1], p[:, 2], 0.0) + s * _relief(p[:, 1], p[:, 2], 1.7)
        return q

    return grid_box_solid(SCAN_SIZE, counts, displace)


def scan_wall(out: Path) -> Path:
    b = Builder("scan_wall")
    t = SCAN_SIZE[0]
    v, f = scan_wall_vertices(SCAN_CELLS)
    b.mesh("scan_wall", "Scan", v, f, "stone")
    b.line("axis", "Axes", (t, 0.0, 0.0), (t, 4.0, 0.0))
    b.line("axis_back", "Axes", (0.0, 0.0, 0.0), (0.0, 4.0, 0.0))
    return b.write(out / "scan_wall.3dm")


def write_binary_ply(path: Path, v: np.ndarray, f: np.ndarray, comment: str) -> Path:
    """Write a triangle mesh as a little-endian binary PLY (double vertices, int indices)."""
    _check_closed(v, f, path.stem)
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"comment {comment}\n"
        f"element vertex {v.shape[0]}\n"
        "property double x\nproperty double y\nproperty double z\n"
        f"element face {f.shape[0]}\n"
        "property list uchar int vertex_indices\nend_header\n"
    )
    rows = np.empty(f.shape[0], dtype=[("n", "u1"), ("idx", "<i4", (3,))])
    rows["n"], rows["idx"] = 3, f
    path.write_bytes(
        header.encode("ascii") + np.ascontiguousarray(v, dtype="<f8").tobytes() + rows.tobytes()
    )
    return path


def scan_wall_ply(out: Path) -> Path:
    """Write the scan wall as a scan file: ``scan_wall.ply``, in millimetres, no axis objects."""
    v, f = scan_wall_vertices(SCAN_PLY_CELLS)
    comment = "rockmech example scan_wall: units mm, built by examples/scenes/build_scenes.py"
    return write_binary_ply(out / "scan_wall.ply", v * MM_PER_M, f, comment)


def two_block_wall(out: Path) -> Path:
    b = Builder("two_block_wall")
    # wall restrained at top and bottom, outer face x = 0.3; the slab bears on its whole top
    b.box("wall", "Walls", (0.0, 0.0, 0.0), (0.3, 3.0, 4.0), "brick")
    b.box("floor", "Floors", (0.0, 0.0, 4.0), (4.0, 3.0, 4.2), "concrete")
    b.line("axis", "Axes", (0.3, 0.0, 0.0), (0.3, 3.0, 0.0))
    b.line("axis_back", "Axes", (0.0, 0.0, 0.0), (0.0, 3.0, 0.0))
    return b.write(out / "two_block_wall.3dm")


Hinge2 = Tuple[float, float]


def _hinge_lines(
    b: Builder, positive: Sequence[Hinge2], negative: Sequence[Hinge2], y0: float, y1: float
) -> None:
    """Add the hinge lines of both sets, (x, z) points run along y from y0 to y1."""
    for suffix, hinges in (("", positive), ("_neg", negative)):
        for label, (x, z) in zip("ABCD", hinges):
            b.line(f"hinge_{label}{suffix}", "Hinges", (x, y0, z), (x, y1, z))


# Side aisle: wall, pier and a segmental arch ring (vault) between them [m].
AISLE_LENGTH = 4.0
AISLE_WALL = (0.0, 0.6, 5.0)  # x0, x1, height
AISLE_PIER = (4.6, 5.05, 5.0)
# Vault: bears on the wall top over x in [0.3, 0.6] and on the whole pier top; intrados a
# segmental arch of span 4 m and rise 1.2 m springing at z = 5; 0.3 m thick (vertically).
AISLE_VAULT_BEARING_X0, AISLE_VAULT_SEGMENTS = 0.3, 12
AISLE_VAULT_RISE, AISLE_VAULT_THICK = 1.2, 0.3


def side_aisle_profiles() -> Dict[str, List[Tuple[float, float]]]:
    """x-z profiles of the side aisle's wall, vault and pier."""
    wx0, wx1, wh = AISLE_WALL
    px0, px1, ph = AISLE_PIER
    span, rise, thick = px0 - wx1, AISLE_VAULT_RISE, AISLE_VAULT_THICK
    radius = (span**2 / 4.0 + rise**2) / (2.0 * rise)
    n = AISLE_VAULT_SEGMENTS
    xs = wx1 + span * np.arange(n + 1) / n
    zi = wh + rise - radius + np.sqrt(radius**2 - (xs - wx1 - span / 2.0) ** 2)
    zi[0] = zi[-1] = wh
    intrados = list(zip(xs.tolist(), zi.tolist()))
    extrados = [(x, z + thick) for x, z in intrados]
    vault = [
        (AISLE_VAULT_BEARING_X0, wh),
        *intrados,
        (px1, ph),
        (px1, ph + thick),
        *extrados[::-1],
        (AISLE_VAULT_BEARING_X0, wh + thick),
    ]
    return {
        "wall": [(wx0, 0.0), (wx1, 0.0), (wx1, wh), (wx0, wh)],
        "vault": vault,
        "pier": [(px0, 0.0), (px1, 0.0), (px1, ph), (px0, ph)],
    }


def side_aisle(out: Path) -> Path:
    b = Builder("side_aisle")
    prof = side_aisle_profiles()
    b.prism_y("wall", "Walls", prof["wall"], 0.0, AISLE_LENGTH, "stone")
    b.prism_y("vault", "Vaults", prof["vault"], 0.0, AISLE_LENGTH, "brick")
    b.prism_y("pier", "Piers", prof["pier"], 0.0, AISLE_LENGTH, "stone")
    wx0, wx1, wh = AISLE_WALL
    px0, px1, ph = AISLE_PIER
    # towards +x: the wall turns about its +x base edge and carries the vault on the -x edge of
    # its bearing; the pier turns about its +x base edge and carries the vault on its -x top edge
    positive = ((wx1, 0.0), (AISLE_VAULT_BEARING_X0, wh), (px0, ph), (px1, 0.0))
    negative = ((wx0, 0.0), (wx1, wh), (px1, ph), (px0, 0.0))
    _hinge_lines(b, positive, negative, 0.0, AISLE_LENGTH)
    return b.write(out / "side_aisle.3dm")


def portal_frame_hinges(
    b: float, h: float, span: float, b_r: float, h_r: float
) -> Tuple[Tuple[Hinge2, ...], Tuple[Hinge2, ...]]:
    """Hinge sets (A, B, C, D) of ``multi_block.portal_frame``, towards +x and towards -x."""
    x_r = b + span
    positive = ((b, 0.0), (0.0, h), (x_r, h_r), (x_r + b_r, 0.0))
    negative = ((0.0, 0.0), (b, h), (x_r + b_r, h_r), (x_r, 0.0))
    return positive, negative


def portal_frame(out: Path) -> Path:
    b = Builder("portal_frame")
    # Makris & Vassiliou's frame: two 0.5 x 4 m columns 3 m apart, a 0.5 m deep beam, 1 m long
    b.box("column_left", "Columns", (0.0, 0.0, 0.0), (0.5, 1.0, 4.0), "stone")
    b.box("beam", "Beams", (0.0, 0.0, 4.0), (4.0, 1.0, 4.5), "stone")
    b.box("column_right", "Columns", (3.5, 0.0, 0.0), (4.0, 1.0, 4.0), "stone")
    _hinge_lines(b, *portal_frame_hinges(0.5, 4.0, 3.0, 0.5, 4.0), 0.0, 1.0)
    return b.write(out / "portal_frame.3dm")


def asym_frame(out: Path) -> Path:
    b = Builder("asym_frame")
    # left column 0.5 x 4.0, right column 0.7 x 3.6, clear span 3.0; the beam is the sheared
    # prism of multi_block.portal_frame: vertical ends, lower edge (0, 4.0) -> (4.2, 3.6)
    b.box("column_left", "Columns", (0.0, 0.0, 0.0), (0.5, 1.0, 4.0), "stone")
    beam = [(0.0, 4.0), (4.2, 3.6), (4.2, 4.1), (0.0, 4.5)]
    b.prism_y("beam", "Beams", beam, 0.0, 1.0, "stone")
    b.box("column_right", "Columns", (3.5, 0.0, 0.0), (4.2, 1.0, 3.6), "stone")
    _hinge_lines(b, *portal_frame_hinges(0.5, 4.0, 3.0, 0.7, 3.6), 0.0, 1.0)
    return b.write(out / "asym_frame.3dm")


# The search example: a 3-storey façade with 6 windows between two return walls.
SEARCH_H, SEARCH_L, SEARCH_T = 10.5, 8.0, 0.5  # façade height, length, thickness [m]
SEARCH_REACH, SEARCH_SIDE_T = 6.0, 0.45  # return walls: length behind the façade, thickness [m]
#: Windows (s0, s1, z0, z1) [m]: two per storey.
SEARCH_WINDOWS = [
    (s0, s0 + 1.2, z0, z0 + h)
    for z0, h in ((0.9, 2.0), (4.4, 1.8), (7.9, 1.6))
    for s0 in (1.5, 5.3)
]


def search_facade(out: Path) -> Path:
    b = Builder("search_facade")
    t, L, H = SEARCH_T, SEARCH_L, SEARCH_H
    holes = [[(s0, z0), (s1, z0), (s1, z1), (s0, z1)] for s0, s1, z0, z1 in SEARCH_WINDOWS]
    # façade: outer face x = 0, inner face x = t, along y in [0, L]
    v, f = slab_solid(
        (0.0, 0.0, 0.0),
        (0.0, 1.0, 0.0),
        (1.0, 0.0, 0.0),
        t,
        [(0.0, 0.0), (L, 0.0), (L, H), (0.0, H)],
        holes,
    )
    b.mesh("facade", "Walls", v, f, "brick")
    w, r = SEARCH_SIDE_T, SEARCH_REACH
    b.box("return_left", "Walls", (t, 0.0, 0.0), (t + r, w, H), "brick")
    b.box("return_right", "Walls", (t, L - w, 0.0), (t + r, L, H), "brick")
    b.box("back_wall", "Walls", (t + r, 0.0, 0.0), (2 * t + r, L, H), "brick")
    # floors abut the façade's inner face and rest on the back wall's face (1 cm clear of
    # the return walls); the roof bears on the wall tops
    for name, z in (("floor_1", 3.5), ("floor_2", 7.0)):
        b.box(name, "Floors", (t, w + 0.01, z), (t + r, L - w - 0.01, z + 0.2), "concrete")
    b.prism_y("roof", "Roof", [(0.0, H), (2 * t + r, H), (t + r / 2, H + 1.6)], 0.0, L, "brick")
    b.line("tie_1", "Ties", (0.0, 2.0, 9.0), (2 * t + r, 2.0, 9.0))
    return b.write(out / "search_facade.3dm")


# ---------------------------------------------------------------------- the palazzo
# A benchmark scene (issue #37), not a shipped example: ``palazzo(out)`` writes it and
# ``palazzo_spec()`` gives its search spec.

#: The block's outer-face plan, x and y [m]: a rectangle, counter-clockwise.
PALAZZO_SIZE = (32.0, 24.0)
#: The courtyard's faces, (x0, x1, y0, y1) [m].
PALAZZO_YARD = (7.0, 25.0, 7.0, 17.0)
#: Thickness of the outer, courtyard and cross walls [m].
PALAZZO_T = {"outer": 0.6, "yard": 0.5, "cross": 0.4}
#: Storey height [m] and number of storeys.
PALAZZO_STOREY, PALAZZO_STOREYS = 3.5, 4
#: Floor and roof slab thickness [m].
PALAZZO_SLAB = 0.25
#: The roof's density, a timber roof's smeared over the slab [kg/m³].
PALAZZO_ROOF_DENSITY = 600.0
#: Window width, sill above the storey's base and height [m].
PALAZZO_WINDOW = (1.2, 0.9, 1.8)
#: Middle cross walls of the long (south, north) and short (west, east) wings.
PALAZZO_CROSS = (5, 2)


def plan_prism(
    outline: Sequence[Tuple[float, float]],
    holes: Sequence[Sequence[Tuple[float, float]]],
    z0: float,
    z1: float,
    lean: float = 0.0,
) -> Tuple[np.ndarray, np.ndarray]:
    """Return a closed mesh of a plan polygon with holes extruded from ``z0`` to ``z1``.

    The top is moved by ``(z1 - z0) * lean`` along x (a prism out of plumb).
    """
    from cad_maths.geometry.polygon import orient_rings, triangulate_polygon

    rings = orient_rings(
        [np.asarray(outline, dtype=float)] + [np.asarray(r, dtype=float) for r in holes]
    )
    pts = np.vstack(rings)
    m = len(pts)
    tris = np.array(triangulate_polygon(rings[0], rings[1:]), dtype=np.int64)
    bottom = np.column_stack([pts, np.full(m, z0)])
    top = np.column_stack([pts[:, 0] + (z1 - z0) * lean, pts[:, 1], np.full(m, z1)])
    faces = [tris[:, ::-1], tris + m]
    start = 0
    for r in rings:
        k = len(r)
        for i in range(k):
            p, q = start + i, start + (i + 1) % k
            faces.append(np.array([[p, q, q + m], [p, q + m, p + m]]))
        start += k
    return np.vstack([bottom, top]), np.vstack(faces)


def _spread(lo: float, hi: float, n: int, t: float) -> List[float]:
    """Return the starts of ``n`` walls of thickness ``t`` cutting [lo, hi] into equal rooms."""
    room = (hi - lo - n * t) / (n + 1)
    return [lo + (k + 1) * room + k * t for k in range(n)]


def palazzo_walls() -> List[Tuple[str, Tuple[float, float], Tuple[float, float], float]]:
    """Return the palazzo's walls: (id, outer-face start, end, thickness), material left.

    The outer ring (``O0`` south, ``O1`` east, ``O2`` north, ``O3`` west) runs
    counter-clockwise; at each corner the next wall butts on the previous one's inner face.
    The courtyard's south and north walls (``CS``, ``CN``) run through its corners and the
    west and east ones (``CW``, ``CE``) stand between them, on their courtyard faces. Cross
    walls (``X…``) join the two rings: one on each side of each courtyard corner (in line
    with the courtyard wall it abuts, at that wall's end), and ``PALAZZO_CROSS`` more across
    each wing.
    """
    lx, ly = PALAZZO_SIZE
    x0, x1, y0, y1 = PALAZZO_YARD
    to, ty, tx = PALAZZO_T["outer"], PALAZZO_T["yard"], PALAZZO_T["cross"]
    walls = [
        ("O0", (to, 0.0), (lx, 0.0), to),
        ("O1", (lx, to), (lx, ly), to),
        ("O2", (lx - to, ly), (0.0, ly), to),
        ("O3", (0.0, ly - to), (0.0, 0.0), to),
        ("CS", (x1 + ty, y0), (x0 - ty, y0), ty),
        ("CN", (x0 - ty, y1), (x1 + ty, y1), ty),
        ("CW", (x0, y0), (x0, y1), ty),
        ("CE", (x1, y1), (x1, y0), ty),
    ]
    # cross walls: material on the left of the line, from the outer ring to the courtyard's
    south, north, west, east = (to, y0 - ty), (y1 + ty, ly - to), (to, x0 - ty), (x1 + ty, lx - to)
    crosses = [
        (x0 - ty, ty, "S"), (x1, ty, "S"), (x0 - ty, ty, "N"), (x1, ty, "N"),
        (y0, ty, "W"), (y1 - ty, ty, "W"), (y0, ty, "E"), (y1 - ty, ty, "E"),
    ]  # fmt: skip
    n_long, n_short = PALAZZO_CROSS
    crosses += [(s, tx, w) for w in "SN" for s in _spread(x0, x1, n_long, tx)]
    crosses += [(s, tx, w) for w in "WE" for s in _spread(y0 + ty, y1 - ty, n_short, tx)]
    for k, (s, t, wing) in enumerate(crosses):
        if wing in "SN":  # along y at x in [s, s + t]: the line x = s, walking -y
            a, b = south if wing == "S" else north
            walls.append((f"X{k}", (s, b), (s, a), t))
        else:  # along x at y in [s, s + t]: the line y = s, walking +x
            a, b = west if wing == "W" else east
            walls.append((f"X{k}", (a, s), (b, s), t))
    return walls


def palazzo_rooms() -> List[Tuple[float, float, float, float]]:
    """Return the rooms between the rings and the cross walls, (x0, x1, y0, y1) [m]."""
    lx, ly = PALAZZO_SIZE
    x0, x1, y0, y1 = PALAZZO_YARD
    to, ty, tx = PALAZZO_T["outer"], PALAZZO_T["yard"], PALAZZO_T["cross"]
    n_long, n_short = PALAZZO_CROSS

    def gaps(lo: float, hi: float, n: int, t: float) -> List[Tuple[float, float]]:
        cuts = [lo] + [v for s in _spread(lo, hi, n, t) for v in (s, s + t)] + [hi]
        return list(zip(cuts[0::2], cuts[1::2]))

    rooms = [
        (to, x0 - ty, to, y0), (x1 + ty, lx - to, to, y0),
        (to, x0 - ty, y1, ly - to), (x1 + ty, lx - to, y1, ly - to),
    ]  # fmt: skip
    rooms += [(a, b, to, y0 - ty) for a, b in gaps(x0, x1, n_long, tx)]
    rooms += [(a, b, y1 + ty, ly - to) for a, b in gaps(x0, x1, n_long, tx)]
    rooms += [(to, x0 - ty, a, b) for a, b in gaps(y0 + ty, y1 - ty, n_short, tx)]
    rooms += [(x1 + ty, lx - to, a, b) for a, b in gaps(y0 + ty, y1 - ty, n_short, tx)]
    return rooms


def palazzo_windows() -> Dict[str, List[Tuple[float, float, float, float]]]:
    """Return each wall's windows in its own elevation, (s0, s1, z0, z1) [m] (s from its start).

    Windows are centred on the rooms behind them: three a storey on the south front, two
    on the north, one on the east and west; one a storey on the courtyard's south and north
    walls and one on the top two storeys of its west and east walls (40 in all).
    """
    lx, ly = PALAZZO_SIZE
    x0, x1, y0, y1 = PALAZZO_YARD
    to, ty = PALAZZO_T["outer"], PALAZZO_T["yard"]
    w, sill, hw = PALAZZO_WINDOW
    rooms = palazzo_rooms()
    south = sorted((a + b) / 2 for a, b, c, _ in rooms if c == to and x0 <= a and b <= x1)
    north = sorted((a + b) / 2 for a, b, c, _ in rooms if c == y1 + ty and x0 <= a and b <= x1)
    west = sorted((c + d) / 2 for a, _, c, d in rooms if a == to and y0 <= c and d <= y1)
    # centres along each wall's own s (walls' starts: see palazzo_walls)
    along = {
        "O0": [south[0] - to, south[2] - to, south[-1] - to],
        "O2": [lx - to - north[1], lx - to - north[-2]],
        "O1": [west[1] - to],
        "O3": [ly - to - west[1]],
        "CS": [x1 + ty - south[3]],
        "CN": [north[2] - (x0 - ty)],
        "CW": [west[1] - y0],
        "CE": [y1 - west[1]],
    }
    out: Dict[str, List[Tuple[float, float, float, float]]] = {}
    for wid, centres in along.items():
        storeys = range(2, PALAZZO_STOREYS) if wid in ("CW", "CE") else range(PALAZZO_STOREYS)
        out[wid] = [
            (c - w / 2, c + w / 2, k * PALAZZO_STOREY + sill, k * PALAZZO_STOREY + sill + hw)
            for k in storeys
            for c in centres
        ]
    return out


def palazzo(out: Path, name: str = "palazzo") -> Path:
    """Write the palazzo block: ``<out>/<name>.3dm``.

    Walls (layer ``Walls``, meshes named by their ids, see ``palazzo_walls``) of
    ``PALAZZO_STOREYS`` storeys with their windows as voids; a floor slab in every room at
    each storey (``floor_<k>_<room>``, layer ``Floors``, abutting the room's walls); a roof
    slab over the wall tops with the courtyard as a hole (``roof``, layer ``Roof``).
    """
    b = Builder(name)
    h = PALAZZO_STOREY * PALAZZO_STOREYS
    windows = palazzo_windows()
    for wid, start, end, t in palazzo_walls():
        a, e = np.asarray(start), np.asarray(end)
        length = float(np.linalg.norm(e - a))
        e_s = (e - a) / length
        v, f = slab_solid(
            (a[0], a[1], 0.0),
            (e_s[0], e_s[1], 0.0),
            (-e_s[1], e_s[0], 0.0),
            t,
            [(0.0, 0.0), (length, 0.0), (length, h), (0.0, h)],
            [[(s0, z0), (s1, z0), (s1, z1), (s0, z1)] for s0, s1, z0, z1 in windows.get(wid, [])],
        )
        b.mesh(wid, "Walls", v, f, "brick")
    for k in range(1, PALAZZO_STOREYS):
        z = k * PALAZZO_STOREY
        for j, (xa, xb, ya, yb) in enumerate(palazzo_rooms()):
            b.box(f"floor_{k}_{j}", "Floors", (xa, ya, z), (xb, yb, z + PALAZZO_SLAB), "concrete")
    lx, ly = PALAZZO_SIZE
    x0, x1, y0, y1 = PALAZZO_YARD
    v, f = plan_prism(
        [(0.0, 0.0), (lx, 0.0), (lx, ly), (0.0, ly)],
        [[(x0, y0), (x0, y1), (x1, y1), (x1, y0)]],
        h,
        h + PALAZZO_SLAB,
    )
    b.mesh("roof", "Roof", v, f, "concrete")
    return b.write(out / f"{name}.3dm")


def palazzo_spec() -> Dict[str, object]:
    """Return the palazzo's search spec: walls of 1800 kg/m³, every room's floor a level.

    Each room's floor at each storey is a level of its own (``floor_<k>_<room>``, concrete,
    half its mass on each wall it abuts: a one-way slab), so that a wall carries the rooms
    beside it, not a whole storey. The roof, one slab on every wall's top, is a light roof
    (``PALAZZO_ROOF_DENSITY``, no thrust) of which each wall carries an equal share
    (``1 / n_walls``; the spec has one share per level). The outer ring's south-east and
    north-west corners and the courtyard walls' junctions with the cross walls at their
    ends are good (bond 0.25 x 0.12 m); every other junction is poor (``default_junction``).
    """
    walls = palazzo_walls()
    levels: List[Dict[str, object]] = [
        {
            "id": f"floor_{k}_{j}",
            "kind": "floor",
            "objects": [f"floor_{k}_{j}"],
            "density": 2400.0,
            "tributary": 0.5,
        }
        for k in range(1, PALAZZO_STOREYS)
        for j in range(len(palazzo_rooms()))
    ]
    levels.append(
        {
            "id": "roof",
            "kind": "roof",
            "objects": ["roof"],
            "density": PALAZZO_ROOF_DENSITY,
            "tributary": 1.0 / len(walls),
            "thrust": False,
        }
    )
    good = [["O0", "O1"], ["O2", "O3"]]
    yard_ends = {"CS": ("X0", "X1"), "CN": ("X2", "X3"), "CW": ("X4", "X5"), "CE": ("X6", "X7")}
    good += [[c, x] for c, xs in yard_ends.items() for x in xs]
    unit = {"length": 0.25, "height": 0.12}
    return {
        "walls": [{"id": w[0], "object": w[0], "density": 1800.0} for w in walls],
        "levels": levels,
        "junctions": [{"walls": pair, "connection": "good", "unit": unit} for pair in good],
        "default_junction": {"connection": "poor"},
    }


SCENES = {
    "rect_wall": rect_wall,
    "statue_column": statue_column,
    "facade": facade,
    "scan_wall": scan_wall,
    "two_block_wall": two_block_wall,
    "side_aisle": side_aisle,
    "portal_frame": portal_frame,
    "asym_frame": asym_frame,
    "search_facade": search_facade,
}
#: Scan-mesh examples (no rhino3dm needed to write them).
SCANS = {"scan_wall_ply": scan_wall_ply}


def build_all(out: Path = HERE) -> List[Path]:
    """Write every example scene (``.3dm``, then the scans) into ``out``; return the paths."""
    out.mkdir(parents=True, exist_ok=True)
    return [build(out) for build in (*SCENES.values(), *SCANS.values())]


def main(argv: Sequence[str] = ()) -> None:
    out = Path(argv[0]) if argv else HERE
    for path in build_all(out):
        print(f"{path}  {path.stat().st_size / 1e6:.2f} MB")


if __name__ == "__main__":
    main(sys.argv[1:])
