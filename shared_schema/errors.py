"""The one exception hierarchy of rockmech.

``RockmechError`` is the base. ``InputError`` carries the path of the offending field
(for example ``mechanisms[2].eta``) or the name of the offending object, so every layer
(CLI, REST, Rhino) can show the same message. The REST service maps these to 4xx answers.

This module has no third-party imports, so that numerical code can raise these errors
without importing pydantic.
"""

from typing import Optional

__all__ = ["GeometryError", "InputError", "RockmechError", "SolverError"]


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
