"""The version of rockmech: the one place it is written.

``pyproject.toml`` reads it from here, ``rockmech.__version__`` re-exports it, and every
document rockmech writes names it. It lives on the lowest floor so that every module may
stamp its outputs with it. The Rhino package files keep copies that tools read as text
(``rhino_plugin/manifest.yml``, ``rhino_plugin/rockmech.rhproj``); a test checks that they
agree with this one.
"""

__version__ = "0.1.0"
