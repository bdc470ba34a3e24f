"""What the Grasshopper components compute, free of Grasshopper.

:func:`spec_from_parameters` makes a single-block spec (A1) from component inputs and names
the geometry it refers to; :func:`constants_from_prepared` computes the constants of any
spec over named :class:`~rhino_plugin.flows.prepared.Prepared` geometry (so other
typologies work from a spec written by hand or by RM_BuildSpec). The components convert
RhinoCommon geometry with ``rhino_plugin.rhino.docscene.prepare`` and call these.

Python 3.9-clean: imported by Rhino 8.
"""

from typing import Any, Dict, List, Optional, Sequence, Tuple

from cad_maths.mechanisms.build import constants_from_spec
from rhino_plugin.flows.mechanisms import ROCKING, checked_number
from rhino_plugin.flows.prepared import PreparedScene
from shared_schema.constants import parse_constants
from shared_schema.errors import InputError
from shared_schema.spec import parse_spec

__all__ = ["constants_from_prepared", "parse_constants_text", "spec_from_parameters"]


def spec_from_parameters(
    mech_id: str,
    rocking: str,
    n_solids: int,
    densities: Sequence[Any],
    has_axis: bool,
    n_cracks: int = 0,
    eta: Optional[Any] = None,
) -> Tuple[Dict[str, Any], List[str]]:
    """Return a single-block spec file (as a dict) and the names it gives the geometry.

    Parameters
    ----------
    mech_id : str
        Mechanism id.
    rocking : str
        ``"two_sided"``/``"one_sided"`` (or ``"TwoSided"``/``"OneSided"``).
    n_solids : int
        Number of solids; they are named ``solid_1`` ... in order.
    densities : sequence of float
        One density [kg/m³] for all solids, or one per solid. Solids of equal density
        form one density group.
    has_axis : bool
        Whether an axis line follows the solids (named ``axis``); required.
    n_cracks : int
        Planar crack objects after the axis (``crack_1`` ...).
    eta : float, optional
        Coefficient of restitution given by the user.

    Returns
    -------
    spec : dict
        ``{"mechanisms": [...]}``, valid for ``shared_schema.spec.parse_spec``.
    names : list of str
        Names of the solids, the axis and the cracks, in that order.
    """
    rock = ROCKING.get(rocking, rocking)
    if rock not in ROCKING.values():
        raise InputError(f"must be one of {sorted(ROCKING.values())}, got {rocking!r}", "rocking")
    if n_solids < 1:
        raise InputError("connect at least one closed solid", "solids")
    if not has_axis:
        raise InputError("connect the rotation axis (a line)", "axis")
    dens = [
        checked_number(d, "the density [kg/m³]", f"densities[{k}]", above=0.0, kind="density")
        for k, d in enumerate(densities)
    ]
    if len(dens) == 1:
        dens = dens * n_solids
    if len(dens) != n_solids:
        raise InputError(
            f"give one density or one per solid ({n_solids}), got {len(dens)}", "densities"
        )
    solids = [f"solid_{k + 1}" for k in range(n_solids)]
    groups: List[Dict[str, Any]] = []
    for name, density in zip(solids, dens):
        same = next((g for g in groups if g["density"] == density), None)
        if same is None:
            groups.append({"objects": [name], "density": density})
        else:
            same["objects"].append(name)
    cracks = [f"crack_{k + 1}" for k in range(n_cracks)]
    mech: Dict[str, Any] = {
        "id": mech_id,
        "typology": "single_block",
        "rocking": rock,
        "groups": groups,
        "axis": {"object": "axis"},
    }
    if cracks:
        mech["cracks"] = [{"object": c} for c in cracks]
    if eta is not None:
        mech["eta"] = checked_number(eta, "eta", "eta", at_least=-1.0, at_most=1.0)
    return {"mechanisms": [mech]}, [*solids, "axis", *cracks]


def constants_from_prepared(
    records: Sequence[Tuple[str, str, Any]],
    spec_text: str,
    *,
    unit_scale: float = 1.0,
    units: str = "meters",
    source: str = "grasshopper",
    tolerance: float = 0.0,
) -> Any:
    """Kinematic constants of a spec over named prepared geometry.

    Parameters
    ----------
    records : sequence of (name, kind, Prepared)
        The geometry the spec names [model units].
    spec_text : str
        A spec file (JSON).
    unit_scale : float
        Metres per model unit [m/unit].
    units : str
        Model unit name.
    source : str
        Scene name recorded in the provenance.
    tolerance : float
        The document's absolute tolerance [m] (contact between solids; 0: the default).

    Returns
    -------
    shared_schema.constants.ConstantsFile
    """
    names = [name for name, _, _ in records]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise InputError(f"names must be unique, repeated: {dup}", "names")
    scene = PreparedScene.from_records(
        [(f"{source}-{k}", n, "", kind, g) for k, (n, kind, g) in enumerate(records)],
        unit_scale=unit_scale,
        units=units,
        path=source,
        tolerance=tolerance,
    )
    spec_file = parse_spec(spec_text, "spec")
    return constants_from_spec(spec_file, scene, scene_name=source, spec_name="spec")


def parse_constants_text(text: Any) -> Any:
    """Parse a constants file from JSON text (as the components pass it along)."""
    if not isinstance(text, str) or not text.strip():
        raise InputError("connect a kinematic-constants JSON text", "constants")
    return parse_constants(text)
