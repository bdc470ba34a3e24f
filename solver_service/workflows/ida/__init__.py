"""Incremental dynamic analysis (being split into modules)."""

from .run import *  # noqa: F403
from .run import __all__  # noqa: F401
