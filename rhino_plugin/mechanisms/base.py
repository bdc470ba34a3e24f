"""What every mechanism typology's builder returns (the registry is ``build.MECHANISMS``).

A builder takes ``(spec, scene, thrust_table)`` (a ``shared_schema.spec.MechanismSpec``, a
scene and a ``thrust.ThrustTable``) and returns one :class:`MechanismSides`;
``build.mechanism_entry`` turns it into an entry of the kinematic-constants file.

Python 3.9-clean: imported by Rhino 8.
"""

from dataclasses import dataclass, field
from typing import Any, Callable, Dict, List, Optional

__all__ = ["Builder", "MechanismSides"]


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
    """

    positive: Dict[str, float]
    negative: Optional[Dict[str, float]]
    eta: Optional[float]
    eta_source: str
    geometry: Dict[str, Any]
    object_ids: List[str]
    warnings: List[str] = field(default_factory=list)
    eta_info: Dict[str, Any] = field(default_factory=dict)


#: A typology's builder: ``(spec, scene, thrust_table) -> MechanismSides``.
Builder = Callable[[Any, Any, Any], MechanismSides]
