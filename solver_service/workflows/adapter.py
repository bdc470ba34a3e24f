"""Convert validated kinematic constants (pydantic, ``shared_schema``) to solver models.

This is the only place where the pydantic models of ``shared_schema.constants`` meet
``solver_service.core``, which stays free of pydantic (docs/architecture.md, floor 1).

Notation
--------
p_eq : equivalent frequency parameter of a side [rad/s]
lam : linearised static load multiplier of a side [-]
phi_ov : overturning rotation of a side [rad]
eta : coefficient of restitution [-]
eta_to_negative, eta_to_positive : restitution of the impacts into the negative and the
    positive side, for asymmetric two-sided mechanisms [-]
"""

from shared_schema.constants import ConstantsFile, Mechanism, SideConstants
from shared_schema.errors import InputError
from solver_service.core.model import RockingModel, RockingSide

__all__ = ["models_from_file", "to_rocking_model"]


def _to_side(side: SideConstants, path: str) -> RockingSide:
    # A validated Mechanism always has these; only a model built without validation
    # (``model_construct``) can lack them.
    for key in ("p_eq", "lam", "phi_ov"):
        if getattr(side, key) is None:
            raise InputError(
                "missing; validate the mechanism before converting it", f"{path}.{key}"
            )
    assert side.p_eq is not None and side.lam is not None and side.phi_ov is not None
    return RockingSide(p_eq=side.p_eq, lam=side.lam, phi_ov=side.phi_ov)


def to_rocking_model(mech: Mechanism) -> RockingModel:
    """Build the solver's model of one validated mechanism.

    Parameters
    ----------
    mech : Mechanism
        A validated mechanism (derived ``p_eq``, ``lam`` and ``phi_ov`` filled in).

    Returns
    -------
    RockingModel
        ``positive``/``negative`` sides from the mechanism's sides (``negative`` absent
        means symmetric), ``eta``, the restitution of each impact direction
        (``eta_to_negative``, ``eta_to_positive``, when the file gives them),
        ``one_sided = (rocking == "one_sided")`` and ``name = id``. A one-sided mechanism
        never rotates negatively, so its ``negative`` side is ignored.

    Raises
    ------
    InputError
        If a side lacks ``p_eq``, ``lam`` or ``phi_ov`` (only possible for a mechanism
        that was not validated).

    Examples
    --------
    >>> from shared_schema.constants import Mechanism
    >>> m = to_rocking_model(Mechanism.model_validate({"id": "W1", "p_eq": 2.15, "lam": 0.25}))
    >>> (m.name, m.positive.phi_ov, m.neg.lam)
    ('W1', 0.25, 0.25)
    """
    one_sided = mech.rocking == "one_sided"
    positive = _to_side(mech.positive, f"{mech.id}.positive")
    negative = None
    if mech.negative is not None and not one_sided:
        negative = _to_side(mech.negative, f"{mech.id}.negative")
    return RockingModel(
        positive=positive,
        negative=negative,
        eta=mech.eta,
        one_sided=one_sided,
        name=mech.id,
        eta_to_negative=None if one_sided else mech.eta_to_negative,
        eta_to_positive=None if one_sided else mech.eta_to_positive,
    )


def models_from_file(cf: ConstantsFile) -> list[RockingModel]:
    """Build the solver's models of every mechanism of a constants file, in file order.

    Parameters
    ----------
    cf : ConstantsFile
        A validated kinematic-constants file.

    Returns
    -------
    list of RockingModel
        One model per mechanism, see ``to_rocking_model``.
    """
    return [to_rocking_model(mech) for mech in cf.mechanisms]
