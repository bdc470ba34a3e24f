"""One typed model per analysis document, defined once (issue #38).

Each module holds one document: ``pulse``, ``boundary``, ``envelope``, ``history``,
``record``, ``check``, ``assess``, ``search`` (``search.json``). Every document derives from
``base.Document``: it refuses unknown keys, starts with ``rockmech_version`` and ``units``,
and has one JSON form, ``to_dict()``, which ``rockmech ... --json``, the files beside a run,
the REST service and Hops all write. The workflows (``solver_service.workflows``) build
them; ``rockmech`` returns them.

The constants document (``constants.json``) is ``shared_schema.constants.ConstantsFile``,
an input format as well; ``ConstantsFile`` here is that model (imported on first use).

The modules are imported on use (nothing here), so a command loads only its own document.
"""

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from shared_schema.constants import ConstantsFile as ConstantsFile

__all__ = ["ConstantsFile"]


def __getattr__(name: str) -> Any:
    """Give ``ConstantsFile`` on first access (PEP 562), so importing this package is free."""
    if name == "ConstantsFile":
        # on first use: importing the package loads no document (nor the constants model)
        from shared_schema.constants import ConstantsFile

        return ConstantsFile
    raise AttributeError(f"module 'shared_schema.documents' has no attribute {name!r}")
