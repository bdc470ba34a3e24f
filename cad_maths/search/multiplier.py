"""The exact static load multiplier λ0 from virtual work (docs/theory.md §1.6, §11.1).

λ0 is the ratio of the work the weights do against a virtual motion of the mechanism at
rest to the work a unit horizontal load proportional to the masses does on it::

    λ0 = [Σ m g δz_G + Σ_k (-F_k)·δx_k] / [Σ m* g d·δx_G]

with ``m`` the masses that weigh on the mechanism (blocks, bearing floors), ``m*`` those
whose inertia it carries (also abutting floors), ``F_k`` the static forces (roof thrust
outward on any motion; tie-bars inward, only on a motion that stretches them: a bar does not
push) and ``d`` the horizontal load direction. It is exact for the
actual block geometry; the rocking constants' ``lam = (K φ_cr - M_F)/(g Q)`` linearises the
same mechanism about its critical rotation and differs from λ0 by a few per cent on squat
blocks (issue #31).

Python 3.9-clean: imported by Rhino 8.
"""

import math
from typing import Optional, Sequence, Tuple, Union

import numpy as np

from cad_maths.search.prism import FirstMoments, Lump
from shared_schema.errors import GeometryError
from shared_schema.rules import G

__all__ = ["Force", "axis_for", "rotation_multiplier", "two_block_multiplier"]

#: A static force: (vector [N], point of application [m]).
Force = Tuple[np.ndarray, np.ndarray]


def axis_for(direction: np.ndarray) -> np.ndarray:
    """Return the unit rotation axis that tips a body standing on it towards ``direction``.

    ``u = e_z × d``: a unit rotation about ``u`` moves a point above the axis by
    ``u × (x - P)``, whose horizontal part points along ``d``.
    """
    d = np.asarray(direction, dtype=float)
    u = np.cross(np.array([0.0, 0.0, 1.0]), d)
    return u / float(np.linalg.norm(u))


def rotation_multiplier(
    weighing: Union[Lump, FirstMoments],
    inertial: Union[Lump, FirstMoments],
    point: np.ndarray,
    direction: np.ndarray,
    forces: Sequence[Force] = (),
    ties: Sequence[Force] = (),
) -> float:
    """λ0 of a rigid body turning about a horizontal axis, tipping towards ``direction``.

    Parameters
    ----------
    weighing : Lump or FirstMoments
        Masses whose weight acts on the body (the blocks and bearing floors).
    inertial : Lump or FirstMoments
        Masses whose horizontal inertia the body carries (``weighing`` plus abutting
        floors).
    point : (3,) float
        A point of the rotation axis [m].
    direction : (3,) float
        Horizontal unit direction of the load and of the collapse.
    forces : sequence of (force, point)
        Static forces [N] and where they act [m], on any motion (thrusts).
    ties : sequence of (force, point)
        Tension-only forces [N] (tie-bars) and where they act [m]: each counts only where
        the motion stretches its bar, i.e. moves its point against the force; on a motion
        towards its anchorage the bar goes slack and carries nothing (a bar does not push).

    Returns
    -------
    float
        λ0 [-]; ``inf`` when the load does no work on the motion (a body that does not
        move along ``direction``).

    Notes
    -----
    For a unit rotation about ``u = e_z × d`` through ``P`` a point moves by
    ``u × (x - P)``; summed over the masses, ``Σ m δx = u × (S - M P)``.

    Examples
    --------
    A 0.5 x 3 m block about its outer base edge: λ0 = b/h.

    >>> from cad_maths.search.prism import WallFrame
    >>> f = WallFrame(np.zeros(3), np.array([0.0, 1, 0]), np.array([1.0, 0, 0]),
    ...               np.array([0.0, 0, 1]), 0.5)
    >>> body = f.prism_lump([np.array([[0.0, 0], [1, 0], [1, 3], [0, 3]])], 1800.0)
    >>> round(rotation_multiplier(body, body, np.zeros(3), np.array([-1.0, 0, 0])), 12)
    0.166666666667
    """
    px, py, pz = (float(v) for v in point)
    dx, dy = float(direction[0]), float(direction[1])
    # u = e_z × d/|d| = (-d_y, d_x, 0)/|d|, and u × r = (u_y r_z, -u_x r_z, u_x r_y - u_y r_x):
    # a point rises by u_x r_y - u_y r_x and moves along d by its height r_z.
    norm = math.hypot(dx, dy)
    ux, uy = -dy / norm, dx / norm
    sx = float(weighing.S[0]) - weighing.mass * px
    sy = float(weighing.S[1]) - weighing.mass * py
    lift = ux * sy - uy * sx
    n_forces = len(forces)
    for k, (f, at) in enumerate([*forces, *ties]):
        rx, ry, rz = float(at[0]) - px, float(at[1]) - py, float(at[2]) - pz
        vx, vy, vz = uy * rz, -ux * rz, ux * ry - uy * rx
        work = float(f[0]) * vx + float(f[1]) * vy + float(f[2]) * vz
        if k >= n_forces and work >= 0.0:
            continue  # a tie whose point moves towards its anchorage: slack
        lift -= work / G
    sway = float(inertial.S[2]) - inertial.mass * pz
    if not sway > 0.0:
        return math.inf
    return lift / sway


def two_block_multiplier(
    lower: Tuple[float, float, float],
    upper: Tuple[float, float, float],
    O: Tuple[float, float],  # noqa: E741 (theory's name of the base hinge)
    C: Tuple[float, float],
    H: Tuple[float, float],
    overburden: float = 0.0,
    overburden_point: Optional[Tuple[float, float]] = None,
) -> float:
    """λ0 of the two-block mechanism O-C-H at rest (theory §2.3), N at its own point.

    Parameters
    ----------
    lower, upper : (mass [kg], x_G [m], z_G [m])
        Blocks 1 (turns about O) and 2 (pinned at C, its hinge H held horizontally), in the
        rocking plane: x along the collapse, z up.
    O, C, H : (float, float)
        Hinges at rest (x, z) [m].
    overburden : float
        Vertical load N on block 2 [N], >= 0.
    overburden_point : (float, float), optional
        Where N acts [m] (default H).

    Returns
    -------
    float
        ``V'(0) / (g Q(0))``, the same quantity as ``two_block_constants``'
        ``lam_static_exact``.

    Notes
    -----
    Block 1 turns at unit rate about O: a point moves by ``(z - z_O, -(x - x_O))``. Block 2
    moves with C and turns at ``ω2 = -δx_C / (z_H - z_C)`` about it so that H stays on its
    restraint. For rectangles with N at H this is
    ``λ0(h1) = (2b/W) [(W + N)/h1 + N/h2]`` (docs/search.md, V1).

    Examples
    --------
    >>> b, h, h1, W = 0.3, 3.0, 1.5, 1.0
    >>> lo = (0.5 / 9.80665, -b / 2, h1 / 2)
    >>> up = (0.5 / 9.80665, -b / 2, h1 + (h - h1) / 2)
    >>> lam = two_block_multiplier(lo, up, (0.0, 0.0), (-b, h1), (0.0, h), overburden=W)
    >>> round(lam, 12) == round((2 * b / W) * ((W + W) / h1 + W / (h - h1)), 12)
    True
    """
    ox, oz = O
    cx, cz = C
    hz = H[1]
    if abs(hz - cz) <= 0.0:
        raise GeometryError("the two-block mechanism locks: C and H are level")
    vcx, vcz = cz - oz, -(cx - ox)
    w2 = -vcx / (hz - cz)

    def upper_velocity(x: float, z: float) -> Tuple[float, float]:
        return vcx + w2 * (z - cz), vcz - w2 * (x - cx)

    m1, x1, z1 = lower
    m2, x2, z2 = upper
    v1 = (z1 - oz, -(x1 - ox))
    v2 = upper_velocity(x2, z2)
    px, pz = overburden_point if overburden_point is not None else H
    vp = upper_velocity(px, pz)
    lift = G * (m1 * v1[1] + m2 * v2[1]) + overburden * vp[1]
    sway = G * (m1 * v1[0] + m2 * v2[0])
    if not sway > 0.0:
        return math.inf
    return lift / sway
