"""Exact mass properties of polyhedral solids and of assemblies of them.

Notation (docs/theory.md §2.1)
-------------------------
V : volume [m³]
M : mass [kg], M = ρ V
r_G : centre of mass [m]
I_G : (3, 3) inertia tensor about the centre of mass [kg m²]
I_O : moment of inertia about a rocking axis through O [kg m²]
"""

import math
from dataclasses import dataclass, field
from typing import Sequence, Tuple

import numpy as np

from shared_schema.errors import InputError

from .mesh import TriMesh
from .validate import check_solid

__all__ = ["MassProps", "combine", "mass_properties"]

#: Faces per chunk of the vectorised integrals (cache-sized; bounds temporary memory).
CHUNK = 1 << 16


def _frozen(array: np.ndarray, shape: Tuple[int, ...]) -> np.ndarray:
    out = np.array(array, dtype=np.float64).reshape(shape)
    out.setflags(write=False)
    return out


@dataclass(frozen=True, eq=False)
class MassProps:
    """Mass properties of a rigid body.

    Attributes
    ----------
    volume : float
        Volume [m³].
    mass : float
        Mass [kg].
    com : (3,) float
        Centre of mass [m].
    inertia_com : (3, 3) float
        Inertia tensor about the centre of mass, world axes [kg m²].
    density : float
        Density [kg/m³]; NaN for an assembly (see :func:`combine`).
    name : str
        Name of the body.
    warnings : tuple of str
        Repairs made to the mesh before integrating (from ``check_solid``).
    """

    volume: float
    mass: float
    com: np.ndarray
    inertia_com: np.ndarray
    density: float
    name: str = "body"
    warnings: Tuple[str, ...] = field(default=())

    def __post_init__(self) -> None:
        object.__setattr__(self, "com", _frozen(self.com, (3,)))
        object.__setattr__(self, "inertia_com", _frozen(self.inertia_com, (3, 3)))
        object.__setattr__(self, "warnings", tuple(self.warnings))

    def inertia_about_axis(self, point: np.ndarray, direction: np.ndarray) -> float:
        """Moment of inertia about an axis (a line) [kg m²].

        Parameters
        ----------
        point : (3,) float
            Any point on the axis [m].
        direction : (3,) float
            Axis direction; its length does not matter.

        Returns
        -------
        float
            I = uᵀ I_G u + M d², with u the unit direction and d the distance from the
            centre of mass to the axis [kg m²].

        Raises
        ------
        InputError
            If ``direction`` is zero or not finite.

        Notes
        -----
        Parallel-axis theorem; gives I_O of docs/theory.md Eq. (7) for a rocking axis.

        Examples
        --------
        >>> p = MassProps(1.0, 12.0, [0, 0, 0], np.diag([1.0, 2.0, 3.0]), 12.0)
        >>> p.inertia_about_axis([0, 1, 0], [0, 0, 5])
        15.0
        """
        d = np.asarray(direction, dtype=np.float64).reshape(3)
        norm = float(np.linalg.norm(d))
        if not (norm > 0.0 and math.isfinite(norm)):
            raise InputError(f"must be a finite non-zero vector, got {direction!r}", "direction")
        u = d / norm
        r = self.com - np.asarray(point, dtype=np.float64).reshape(3)
        perp = r - np.dot(r, u) * u
        return float(u @ self.inertia_com @ u + self.mass * np.dot(perp, perp))

    def second_moment_about_plane(self, point: np.ndarray, normal: np.ndarray) -> float:
        """Second moment of the mass about a plane, the integral of (distance)² dm [kg m²].

        Parameters
        ----------
        point : (3,) float
            Any point of the plane [m].
        normal : (3,) float
            Normal of the plane; its length does not matter.

        Returns
        -------
        float
            ``nᵀ C_G n + M ((r_G - p)·n)²`` with ``C_G = tr(I_G)/2 · 1 - I_G`` the second-moment
            tensor about the centre of mass [kg m²].

        Raises
        ------
        InputError
            If ``normal`` is zero or not finite.

        Notes
        -----
        For the horizontal plane through a rocking axis it is the sum of ``m δx²`` over the
        body for a unit virtual rotation, the denominator of the participating mass of the
        code's kinematic check (docs/theory.md §11.1).

        Examples
        --------
        A 1 x 1 x 3 m box of 3 kg centred at z = 1.5 m, about its base plane: M h²/3 = 9.

        >>> p = MassProps(3.0, 3.0, [0, 0, 1.5], np.diag([2.5, 2.5, 0.5]), 1.0)
        >>> round(p.second_moment_about_plane([0, 0, 0], [0, 0, 2]), 12)
        9.0
        """
        d = np.asarray(normal, dtype=np.float64).reshape(3)
        norm = float(np.linalg.norm(d))
        if not (norm > 0.0 and math.isfinite(norm)):
            raise InputError(f"must be a finite non-zero vector, got {normal!r}", "normal")
        n = d / norm
        c_g = 0.5 * float(np.trace(self.inertia_com)) * np.eye(3) - self.inertia_com
        dist = float(np.dot(self.com - np.asarray(point, dtype=np.float64).reshape(3), n))
        return float(n @ c_g @ n + self.mass * dist * dist)


def _dot(x: np.ndarray, y: np.ndarray) -> float:
    """Sum of x * y without BLAS (single-threaded, same cost on a busy machine)."""
    return float(np.einsum("i,i->", x, y))


def _integrals(local: np.ndarray, faces: np.ndarray) -> Tuple[float, np.ndarray, np.ndarray]:
    """Volume integrals of 1, x and x xᵀ over a closed, outward mesh (coordinates local).

    Each triangle (a, b, c) and the local origin span a tetrahedron of signed volume
    det/6 with det = a · (b × c). Over it, ∫x dV = det (a + b + c)/24 and
    ∫x xᵀ dV = det (a aᵀ + b bᵀ + c cᵀ + s sᵀ)/120 with s = a + b + c (the canonical
    tetrahedron's covariance). Summing over the faces gives the solid's integrals by the
    divergence theorem.
    """
    x, y, z = np.ascontiguousarray(local.T)
    vol6 = 0.0
    first = np.zeros(3)
    second = np.zeros(6)  # xx, xy, xz, yy, yz, zz
    for start in range(0, len(faces), CHUNK):
        i, j, k = faces[start : start + CHUNK].T
        a = (x[i], y[i], z[i])
        b = (x[j], y[j], z[j])
        c = (x[k], y[k], z[k])
        det = a[0] * (b[1] * c[2] - b[2] * c[1])
        det += a[1] * (b[2] * c[0] - b[0] * c[2])
        det += a[2] * (b[0] * c[1] - b[1] * c[0])
        s = (a[0] + b[0] + c[0], a[1] + b[1] + c[1], a[2] + b[2] + c[2])
        vol6 += float(det.sum())
        # einsum, not `@`: a 1-D `@` is a threaded BLAS dot, which on a loaded machine
        # spins its threads (0.15 s became 2.4 s on the 1M-triangle wall); einsum is not
        first += (_dot(det, s[0]), _dot(det, s[1]), _dot(det, s[2]))
        m = 0
        for p in range(3):
            for q in range(p, 3):
                second[m] += _dot(det, a[p] * a[q] + b[p] * b[q] + c[p] * c[q] + s[p] * s[q])
                m += 1
    second = second[[[0, 1, 2], [1, 3, 4], [2, 4, 5]]]
    return vol6 / 6.0, first / 24.0, second / 120.0


def mass_properties(mesh: TriMesh, density: float, *, repair: bool = True) -> MassProps:
    """Exact mass properties of a homogeneous polyhedral solid.

    Parameters
    ----------
    mesh : TriMesh
        The solid [m]. It is checked (and, with ``repair``, repaired) by
        :func:`cad_maths.geometry.validate.check_solid` first, so an open mesh never
        yields a volume.
    density : float
        Density ρ [kg/m³], finite and > 0.
    repair : bool, optional
        Passed to ``check_solid``; the repairs made are listed in ``warnings``.

    Returns
    -------
    MassProps
        Volume, mass, centre of mass and inertia tensor about it.

    Raises
    ------
    InputError
        If ``density`` is not finite and positive (field ``density``).
    GeometryError
        If the mesh is not a valid solid.

    Notes
    -----
    Divergence theorem over signed tetrahedra (see ``_integrals``), exact for a
    polyhedron up to rounding. Coordinates are shifted to the bounding-box centre first,
    so a scene 100 km from the origin loses no accuracy. Then
    I_G = tr(C_G) 1 - C_G with C_G = ρ ∫(x - r_G)(x - r_G)ᵀ dV (docs/theory.md §2.1).

    Examples
    --------
    >>> from cad_maths.geometry.mesh import TriMesh
    >>> tet = TriMesh(np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]),
    ...               np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]), "tet")
    >>> p = mass_properties(tet, 600.0)
    >>> round(p.mass, 12), p.com.round(12).tolist()
    (100.0, [0.25, 0.25, 0.25])
    """
    try:
        rho = float(density)
    except (TypeError, ValueError):
        rho = math.nan
    if not (math.isfinite(rho) and rho > 0.0):
        raise InputError(
            f"must be finite and > 0 [kg/m³] for object '{mesh.name}', got {density!r}",
            "density",
        )
    solid, notes = check_solid(mesh, repair=repair)
    v, f = solid.vertices, solid.faces
    used = np.zeros(len(v), dtype=bool)
    used[f.ravel()] = True
    ref = 0.5 * (v[used].min(axis=0) + v[used].max(axis=0))
    volume, first, second = _integrals(v - ref, f)
    c = first / volume
    mass = rho * volume
    cov = rho * second - mass * np.outer(c, c)
    inertia = np.trace(cov) * np.eye(3) - cov
    inertia = 0.5 * (inertia + inertia.T)
    return MassProps(volume, mass, ref + c, inertia, rho, mesh.name, tuple(notes))


def combine(parts: Sequence[MassProps], name: str = "assembly") -> MassProps:
    """Mass properties of a rigid assembly of bodies.

    Parameters
    ----------
    parts : sequence of MassProps
        The bodies (any densities).
    name : str, optional
        Name of the assembly.

    Returns
    -------
    MassProps
        M = Σ M_i, r_G = Σ M_i r_i / M, I_G = Σ [I_i + M_i (|d_i|² 1 - d_i d_iᵀ)] with
        d_i = r_i - r_G, V = Σ V_i; density NaN; warnings concatenated.

    Raises
    ------
    InputError
        If ``parts`` is empty (field ``parts``).

    Notes
    -----
    docs/theory.md §2.1: M = Σ ρ_j V_j, r_G = Σ ρ_j V_j r_Gj / M, inertia summed over the
    density groups after the parallel-axis shift.

    Examples
    --------
    >>> a = MassProps(1.0, 2.0, [0, 0, 0], np.zeros((3, 3)), 2.0)
    >>> b = MassProps(1.0, 2.0, [2, 0, 0], np.zeros((3, 3)), 2.0)
    >>> ab = combine([a, b])
    >>> ab.com.tolist(), ab.inertia_about_axis([1, 0, 0], [0, 0, 1])
    ([1.0, 0.0, 0.0], 4.0)
    """
    parts = list(parts)
    if not parts:
        raise InputError("needs at least one body", "parts")
    # Work relative to one part's centre of mass, for scenes far from the origin.
    ref = parts[0].com
    mass = math.fsum(p.mass for p in parts)
    volume = math.fsum(p.volume for p in parts)
    c = sum((p.mass * (p.com - ref) for p in parts), np.zeros(3)) / mass
    inertia = np.zeros((3, 3))
    for p in parts:
        d = p.com - ref - c
        inertia += p.inertia_com + p.mass * (np.dot(d, d) * np.eye(3) - np.outer(d, d))
    notes = tuple(w for p in parts for w in p.warnings)
    return MassProps(volume, mass, ref + c, inertia, math.nan, name, notes)
