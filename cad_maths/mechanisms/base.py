"""What every mechanism typology's builder returns (the registry is ``build.MECHANISMS``).

A builder takes ``(spec, scene, thrust_table)`` (a ``shared_schema.spec.MechanismSpec``, a
scene and a ``thrust.ThrustTable``) and returns one :class:`MechanismSides`;
``build.mechanism_entry`` turns it into an entry of the kinematic-constants file.

Python 3.9-clean: imported by Rhino 8.
"""

from dataclasses import dataclass, field
from typing import Any, Callable, Dict, List, Optional

__all__ = ["Builder", "MechanismSides", "virtual_work_of"]


@dataclass
class MechanismSides:
    """The constants of one mechanism, as its typology computes them.

    Attributes
    ----------
    positive : dict
        Physical constants of the positive side: ``I0`` [kg m²], ``K`` [N m/rad], ``Q``
        [kg m], ``phi_cr`` [rad], ``M_F`` [N m] (docs/theory.md §1.2).
    negative : dict, optional
        The same for the negative side of a two-sided mechanism; None for one-sided rocking.
    eta : float, optional
        Computed coefficient of restitution [-], or None where the typology gives none.
    eta_source : str
        The rule that gave ``eta`` (``shared_schema.constants.EtaSource``).
    geometry : dict
        Geometry summary for the constants file (masses, centres, lever arms...).
    object_ids : list of str
        Ids of the scene objects used.
    warnings : list of str
        Notes for the user (mesh repairs, assumptions).
    eta_info : dict
        Details of the restitution rule, kept in the geometry summary.
    virtual_work : dict
        Per side (``"positive"``, ``"negative"``), the virtual-work quantities at rest for
        the code's kinematic check: ``alpha0`` [-], ``mass`` [kg], ``S`` [kg m], ``J``
        [kg m²] (``shared_schema.constants.VirtualWork``, docs/theory.md §11.1).
    """

    positive: Dict[str, float]
    negative: Optional[Dict[str, float]]
    eta: Optional[float]
    eta_source: str
    geometry: Dict[str, Any]
    object_ids: List[str]
    warnings: List[str] = field(default_factory=list)
    eta_info: Dict[str, Any] = field(default_factory=dict)
    virtual_work: Dict[str, Dict[str, float]] = field(default_factory=dict)


#: A typology's builder: ``(spec, scene, thrust_table) -> MechanismSides``.
Builder = Callable[[Any, Any, Any], MechanismSides]


def virtual_work_of(details: Dict[str, float], alpha0_key: str) -> Optional[Dict[str, float]]:
    """Return a linkage side's virtual-work quantities from its ``details``, if computed.

    Parameters
    ----------
    details : dict
        A linkage result's details with ``S0``, ``J0``, ``Jb0`` (the per-block second
        moment), ``mass0`` and ``alpha0_key``.
    alpha0_key : str
        The key of the exact static multiplier at rest (``lam_static_exact``,
        ``lam_static``).

    Returns
    -------
    dict or None
        ``alpha0``, ``mass`` [kg], ``S`` [kg m], ``J`` and ``J_blocks`` [kg m²]; None where
        the blocks had no second moments (docs/theory.md §11.1).
    """
    keys = ("S0", "J0", "Jb0", "mass0", alpha0_key)
    if not all(k in details for k in keys):
        return None
    return {
        "alpha0": float(details[alpha0_key]),
        "mass": float(details["mass0"]),
        "S": float(details["S0"]),
        "J": float(details["J0"]),
        "J_blocks": float(details["Jb0"]),
    }
