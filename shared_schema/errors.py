"""The one exception hierarchy of rockmech.

``RockmechError`` is the base. ``InputError`` carries the path of the offending field
(for example ``mechanisms[2].eta``) or the name of the offending object, so every layer
(CLI, REST, Rhino) can show the same message. The REST service maps these to 4xx answers.

This module has no third-party imports, so that numerical code can raise these errors
without importing pydantic.
"""

from typing import Optional

__all__ = [
    "GeometryError",
    "InputError",
    "RockmechError",
    "SolverError",
    "per_side_error",
    "wrong_type",
]


class RockmechError(Exception):
    """Base class of every error rockmech raises on purpose."""


class InputError(RockmechError, ValueError):
    """An input value, file or object is invalid.

    Parameters
    ----------
    message : str
        What is wrong, in words a user can act on.
    field : str, optional
        Path of the offending field or name of the offending object, e.g. ``"eta"`` or
        ``"mechanisms[1].p_eq"``. It is prefixed to the message.
    """

    def __init__(self, message: str, field: Optional[str] = None) -> None:
        self.field = field
        self.reason = message
        super().__init__(f"{field}: {message}" if field else message)


class GeometryError(RockmechError):
    """A geometric object cannot be used (open mesh, zero volume, axis off the body, ...)."""


class SolverError(RockmechError):
    """A numerical procedure failed in a way the inputs do not explain."""


def per_side_error(
    owner: str, name: str, positive: object, negative: object, one_sided: bool
) -> AttributeError:
    """Build the error for a side's constant read on a whole mechanism (``mech.p_eq``).

    A mechanism's constants live per side (``.positive.p_eq``, ``.negative.p_eq``); the
    message says so and gives both values, so a script's first guess leads to the fix.

    Parameters
    ----------
    owner : str
        The mechanism, as the message names it (its class and id).
    name : str
        The constant asked for (``p_eq``, ``lam``, ``phi_ov``, ...).
    positive, negative : object
        Its value on each side (``negative`` None: the same as the positive side).
    one_sided : bool
        One-sided rocking (only the positive side rocks).
    """
    if one_sided:
        where = f"use .positive.{name} (= {positive!r}; one-sided rocking has only that side)"
    elif negative is None:
        where = f"use .positive.{name} (= {positive!r}; symmetric: the negative side is the same)"
    else:
        where = f"use .positive.{name} (= {positive!r}) or .negative.{name} (= {negative!r})"
    return AttributeError(f"{owner} has no {name} of its own: the constants live per side; {where}")


def wrong_type(value: object, field: str, expected: str, hint: str = "") -> InputError:
    """Build the error for an argument of another type: what it takes, what it got, the fix.

    Parameters
    ----------
    value : object
        The argument as given.
    field : str
        The argument's name.
    expected : str
        What it takes, in words (``"a RockingModel"``).
    hint : str
        How to get one from what was given, if there is a way (appended after ``;``).

    Examples
    --------
    >>> str(wrong_type("W1", "model", "a RockingModel", "models_from_constants(cf) gives them"))
    'model: must be a RockingModel, got str; models_from_constants(cf) gives them'
    """
    tail = f"; {hint}" if hint else ""
    return InputError(f"must be {expected}, got {type(value).__name__}{tail}", field)
