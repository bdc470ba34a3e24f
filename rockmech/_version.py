"""The version of rockmech (written once, in ``shared_schema.version``)."""

from shared_schema.version import __version__

__all__ = ["__version__"]
