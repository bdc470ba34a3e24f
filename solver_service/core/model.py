"""The linearised rocking model of one mechanism (docs/theory.md §1).

Notation
--------
phi : rotation of the mechanism, positive in the direction of collapse [rad]
x : normalised rotation used by the integrators, ``x = phi / phi_ov`` on the side in
    motion (so ``|x|`` *is* the ratio ``|phi|/phi_ov`` that the method reports) [-]
p_eq : equivalent frequency parameter of a side [rad/s]
lam : linearised static load multiplier of a side (uplift acceleration / g) [-]
phi_ov : overturning rotation of a side [rad]
eta : coefficient of restitution on the angular velocity at impact [-];
    ``0 <= eta <= 1`` for two-sided rocking, ``-1 <= eta <= 0`` for one-sided rebound.

Equation of motion in ``x`` (Eq. 3 of docs/theory.md divided by ``lam``), on side ``s = ±1``::

    x'' = p_s**2 * (x - s - a_g(t) / (g * lam_s))

with Housner's sign convention: a positive ground acceleration ``a_g`` opposes positive
rotation. At an impact on ``x = 0`` the angular velocity is scaled by ``eta``; in ``x`` this
becomes ``x' -> eta * (phi_ov_old / phi_ov_new) * x'`` (theory §1.8).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Optional

from shared_schema.errors import InputError, per_side_error, wrong_type
from shared_schema.rules import (
    G,
    check_eta,
    check_non_negative,
    check_number,
    check_positive,
)

__all__ = [
    "G",
    "RockingModel",
    "RockingSide",
    "check_eta",
    "check_non_negative",
    "check_number",
    "check_positive",
    "require_model",
    "require_models",
]


@dataclass(frozen=True)
class RockingSide:
    """Constants of one rocking side.

    Parameters
    ----------
    p_eq : float
        Equivalent frequency parameter [rad/s], > 0.
    lam : float
        Linearised static load multiplier [-], > 0.
    phi_ov : float, optional
        Overturning rotation [rad], > 0. Defaults to ``lam`` (single block: φ_ov = λ = α).
    """

    p_eq: float
    lam: float
    phi_ov: float = float("nan")

    def __post_init__(self) -> None:
        object.__setattr__(self, "p_eq", check_positive(self.p_eq, "p_eq"))
        object.__setattr__(self, "lam", check_positive(self.lam, "lam"))
        phi_ov = self.lam if math.isnan(self.phi_ov) else self.phi_ov
        object.__setattr__(self, "phi_ov", check_positive(phi_ov, "phi_ov"))


@dataclass(frozen=True)
class RockingModel:
    """A mechanism as the solver sees it: two sides, restitution and the rocking kind.

    Parameters
    ----------
    positive : RockingSide
        Constants for positive rotation (the collapse direction).
    negative : RockingSide, optional
        Constants for negative rotation (two-sided rocking). Defaults to ``positive``
        (symmetric mechanism). Ignored for one-sided rocking.
    eta : float, optional
        Coefficient of restitution [-]. Required for time histories; one-sided envelopes
        do not need it. Two-sided: ``0 <= eta <= 1``; one-sided: ``-1 <= eta <= 0``.
    one_sided : bool
        True for a mechanism that can only rotate positively (e.g. a façade restrained by
        transverse walls); it rebounds off the restraint at ``x = 0``.
    name : str
        Identifier used in messages and outputs.
    eta_to_negative, eta_to_positive : float, optional
        Two-sided rocking of an asymmetric mechanism: the restitution at an impact after
        which the body rocks on its negative (positive) side [-], each in [0, 1], given
        together. Every integrator applies the value of the direction entered at each
        impact (theory §1.8, ``eta_into``); without them ``eta`` serves both impacts.
    """

    positive: RockingSide
    negative: Optional[RockingSide] = None
    eta: Optional[float] = None
    one_sided: bool = False
    name: str = field(default="mechanism")
    eta_to_negative: Optional[float] = None
    eta_to_positive: Optional[float] = None

    def __post_init__(self) -> None:
        if self.negative is None:
            object.__setattr__(self, "negative", self.positive)
        if self.eta is not None:
            object.__setattr__(self, "eta", check_eta(self.eta, self.one_sided))
        directional = {
            "eta_to_negative": self.eta_to_negative,
            "eta_to_positive": self.eta_to_positive,
        }
        given = [k for k, v in directional.items() if v is not None]
        if given:
            if len(given) == 1 or self.one_sided:
                raise InputError(
                    "eta_to_negative and eta_to_positive go together, for two-sided rocking",
                    f"{self.name}.{given[0]}",
                )
            for key, value in directional.items():
                object.__setattr__(self, key, check_eta(value, False, f"{self.name}.{key}"))

    @classmethod
    def symmetric(
        cls,
        p_eq: float,
        lam: float,
        eta: Optional[float] = None,
        *,
        phi_ov: Optional[float] = None,
        one_sided: bool = False,
        name: str = "mechanism",
    ) -> RockingModel:
        """Build a mechanism with the same constants on both sides.

        Examples
        --------
        >>> m = RockingModel.symmetric(p_eq=2.0, lam=0.2, eta=0.9)
        >>> m.negative.lam
        0.2
        """
        side = RockingSide(p_eq, lam, float("nan") if phi_ov is None else phi_ov)
        return cls(positive=side, negative=side, eta=eta, one_sided=one_sided, name=name)

    if not TYPE_CHECKING:  # for type checkers the fields are the attributes, as they are

        def __getattr__(self, name: str) -> Any:
            """Point a side's constant read on the model (``model.p_eq``) to its side."""
            if name in RockingSide.__dataclass_fields__:
                negative = None if self.negative is self.positive else getattr(self.neg, name)
                raise per_side_error(
                    f"RockingModel {self.name!r}",
                    name,
                    getattr(self.positive, name),
                    negative,
                    self.one_sided,
                )
            raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    @property
    def neg(self) -> RockingSide:
        """Constants of the negative side (equal to ``positive`` when symmetric)."""
        assert self.negative is not None
        return self.negative

    @property
    def is_symmetric(self) -> bool:
        """True when both sides have the same constants (or the mechanism is one-sided)."""
        return self.one_sided or self.positive == self.negative

    @property
    def is_directional(self) -> bool:
        """True when the two impact directions have different restitution."""
        return self.eta_to_negative is not None and self.eta_to_negative != self.eta_to_positive

    def eta_into(self, s: int) -> float:
        """Restitution [-] at an impact after which the body rocks on side ``s`` (±1).

        One-sided rocking and mechanisms without directional values return ``eta``
        (``require_eta``). Theory §1.8.

        Examples
        --------
        >>> side = RockingSide(2.0, 0.2)
        >>> m = RockingModel(side, eta=0.9, eta_to_negative=0.9, eta_to_positive=0.8)
        >>> m.eta_into(1), m.eta_into(-1)
        (0.8, 0.9)
        """
        eta = self.require_eta()
        if self.one_sided or self.eta_to_negative is None or self.eta_to_positive is None:
            return eta
        return self.eta_to_positive if s > 0 else self.eta_to_negative

    def require_eta(self) -> float:
        """Return ``eta``, or raise a clear error when a time-domain analysis needs it."""
        if self.eta is None:
            kind = "one-sided" if self.one_sided else "two-sided"
            raise InputError(
                f"a time-domain analysis of a {kind} mechanism needs a coefficient of "
                "restitution; give eta",
                f"{self.name}.eta",
            )
        return self.eta


def _model_hint(value: object) -> str:
    """How to get a ``RockingModel`` from ``value``, for the message."""
    if hasattr(value, "mechanisms"):  # a ConstantsFile
        return "a constants file holds one per mechanism: rockmech.models_from_constants(cf)"
    if hasattr(value, "positive") and hasattr(value, "id"):  # one mechanism of a file
        return "rockmech.models_from_constants(cf) gives each mechanism's model"
    if isinstance(value, str):
        return (
            "build one with RockingModel.symmetric(p_eq=..., lam=..., eta=...) or read a "
            "constants file with rockmech.models_from_constants(path)"
        )
    return ""


def require_model(value: object, field: str = "model") -> RockingModel:
    """Return ``value`` if it is a ``RockingModel``; else an ``InputError`` saying what to pass.

    Examples
    --------
    >>> require_model("W1")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    shared_schema.errors.InputError: model: must be a RockingModel, got str; build one with ...
    """
    if isinstance(value, RockingModel):
        return value
    raise wrong_type(value, field, "a RockingModel", _model_hint(value))


def require_models(values: object, field: str = "models") -> list[RockingModel]:
    """Return a sequence of ``RockingModel`` as a list; one model or another type is refused."""
    if isinstance(values, RockingModel):
        raise wrong_type(values, field, "a sequence of RockingModels", "give a list of it: [model]")
    if isinstance(values, (str, bytes)) or not hasattr(values, "__iter__"):
        raise wrong_type(values, field, "a sequence of RockingModels", _model_hint(values))
    return [require_model(v, f"{field}[{k}]") for k, v in enumerate(values)]
