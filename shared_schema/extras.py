"""Optional dependencies ("extras") of rockmech: one clear error when one is missing.

``pip install rockmech`` gives the solver, the command line and its plots. Heavy or
specialised parts come with extras: ``geometry`` (reading ``.3dm`` scenes, mesh cuts and
contact polygons), ``service`` (the REST service and Hops), ``dask`` (``ida --scheduler``),
``parquet`` (``ida --peaks``).
Code that needs one of them imports it through :func:`require`, which raises
:class:`MissingExtra` naming the module and the exact install line. The command line turns
that into exit status 2 and the line on stderr; the REST service into a 501 answer with the
same message.

Standard library only: every floor may import this module (Rhino 8's CPython 3.9 too).
"""

import importlib
from types import ModuleType
from typing import Dict, Optional

from shared_schema.errors import RockmechError

__all__ = ["EXTRAS", "MissingExtra", "extra_for", "install_line", "require"]

#: The extra that installs each optional top-level module (pyproject.toml's
#: ``[project.optional-dependencies]``; a test checks the two agree).
EXTRAS: Dict[str, str] = {
    "rhino3dm": "geometry",
    "trimesh": "geometry",
    "manifold3d": "geometry",
    "shapely": "geometry",
    "fastapi": "service",
    "uvicorn": "service",
    "multipart": "service",
    "pydantic_settings": "service",
    "ghhops_server": "service",
    "werkzeug": "service",
    "dask": "dask",
    "distributed": "dask",
    "pyarrow": "parquet",
}


def install_line(extra: str) -> str:
    """Return the command that installs an extra, e.g. ``pip install 'rockmech[geometry]'``."""
    return f"pip install 'rockmech[{extra}]'"


def extra_for(module: str) -> Optional[str]:
    """Return the extra that installs ``module`` (a dotted name is fine), or None if unknown."""
    return EXTRAS.get(module.split(".", 1)[0])


class MissingExtra(RockmechError, ImportError):
    """An optional dependency is not installed.

    It is also an ``ImportError``, so code that already falls back on a missing import keeps
    doing so.

    Parameters
    ----------
    module : str
        The module that cannot be imported (``name`` holds it too, as in ``ImportError``).
    extra : str
        The extra that installs it.
    purpose : str, optional
        What it is needed for, in a few words ("to read .3dm scenes").

    Attributes
    ----------
    install : str
        The exact install line, ``pip install 'rockmech[<extra>]'``.
    """

    def __init__(self, module: str, extra: str, purpose: Optional[str] = None) -> None:
        self.module = module
        self.extra = extra
        self.install = install_line(extra)
        need = f" (needed {purpose})" if purpose else ""
        super().__init__(
            f"{module} is not installed{need}; install the {extra!r} extra: {self.install}"
        )
        self.name = module


def require(module: str, extra: str, purpose: Optional[str] = None) -> ModuleType:
    """Import and return ``module``, or raise :class:`MissingExtra` naming ``extra``.

    Parameters
    ----------
    module : str
        Dotted module name, e.g. ``"shapely"`` or ``"dask.distributed"``.
    extra : str
        The extra of rockmech that installs it.
    purpose : str, optional
        What it is needed for, for the message.

    Returns
    -------
    module
        The imported module.

    Raises
    ------
    MissingExtra
        If the module, or a module it needs, is not installed; the message names the missing
        module and gives ``pip install 'rockmech[<extra>]'``.

    Examples
    --------
    >>> require("json", "none").dumps(1)
    '1'
    """
    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as exc:
        raise MissingExtra(exc.name or module, extra, purpose) from exc
