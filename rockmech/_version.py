"""The version of rockmech: the one place it is written (pyproject.toml reads it from here).

The Rhino package files keep copies that tools read as text (``rhino_plugin/manifest.yml``,
``rhino_plugin/rockmech.rhproj``); a test checks that they agree with this one.
"""

__version__ = "0.1.0"
