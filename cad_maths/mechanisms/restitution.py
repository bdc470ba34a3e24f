"""Coefficients of restitution (theory §3).

Two-sided rocking uses Housner's momentum balance about the new pivot in its general form
(Eq. 25 generalised, §3.1)::

    eta = (I_G + M r_OG . r_O'G) / I_O'

with ``r_OG``, ``r_O'G`` the vectors from the old and new pivot to the centre of mass (in the
rocking plane) and ``I_O'`` the inertia about the new pivot. For a body whose two pivots are
symmetric this is ``1 - 2 M R² sin²(alpha) / I_O``.

One-sided rocking (rebound off a restraint) has three candidate rules that the published
tables cannot tell apart (theory §3.2, §8); ``one_sided_eq26`` is the default:

* ``one_sided_eq26``: ``1 - 2 M R² cos²(alpha) / I_O`` (Eq. 26);
* ``one_sided_alt``: ``1 - 2 M R² / I_O``;
* ``one_sided_energy``: ``(1 - 2 M R² sin²(alpha)/I_O)² (1 - 2 M R² cos²(alpha)/I_O)``.
"""

import math
from typing import Any

import numpy as np

from shared_schema.errors import InputError

__all__ = ["ONE_SIDED_RULES", "housner_general", "one_sided"]

#: One-sided rules and their formulas, for provenance.
ONE_SIDED_RULES = {
    "one_sided_eq26": "1 - 2 M R^2 cos^2(alpha) / I_O (Eq. 26)",
    "one_sided_alt": "1 - 2 M R^2 / I_O",
    "one_sided_energy": "(1 - 2 M R^2 sin^2(alpha)/I_O)^2 (1 - 2 M R^2 cos^2(alpha)/I_O)",
}


def housner_general(mass: float, i_g: float, r_og: Any, r_o2g: Any, i_o2: float) -> float:
    """Angular-velocity ratio at an impact that moves the pivot from O to O'.

    Parameters
    ----------
    mass : float
        Mass [kg].
    i_g : float
        Moment of inertia about the axis through the centre of mass, parallel to the pivots
        [kg m²].
    r_og, r_o2g : (3,) float
        Vectors from the old and the new pivot line to the centre of mass, perpendicular to
        the axis [m].
    i_o2 : float
        Moment of inertia about the new pivot [kg m²].

    Notes
    -----
    theory §3.1 (Housner 1963, angular momentum about the new pivot conserved).

    Examples
    --------
    A rectangular block 0.5 m x 3 m (R, alpha as in Housner):

    >>> b, h, m = 0.5, 3.0, 1.0
    >>> i_g = m * (b * b + h * h) / 12
    >>> i_o = i_g + m * (b * b + h * h) / 4
    >>> round(housner_general(m, i_g, [-b / 2, 0, h / 2], [b / 2, 0, h / 2], i_o), 6)
    0.959459
    """
    dot = float(np.dot(np.asarray(r_og, dtype=float), np.asarray(r_o2g, dtype=float)))
    return (i_g + mass * dot) / i_o2


def one_sided(
    mass: float, r: float, alpha: float, i_o: float, rule: str = "one_sided_eq26"
) -> float:
    """One-sided (rebound) restitution by ``rule`` (see ``ONE_SIDED_RULES``)."""
    k = 2.0 * mass * r * r / i_o
    if rule == "one_sided_eq26":
        return 1.0 - k * math.cos(alpha) ** 2
    if rule == "one_sided_alt":
        return 1.0 - k
    if rule == "one_sided_energy":
        return (1.0 - k * math.sin(alpha) ** 2) ** 2 * (1.0 - k * math.cos(alpha) ** 2)
    raise InputError(f"must be one of {sorted(ONE_SIDED_RULES)}, got {rule!r}", "eta_rule")
