"""Shared file formats of rockmech: the kinematic-constants file, specs and API models.

This package is imported by Rhino 8 (CPython 3.9), the headless tools and the service.
Importing the package itself is cheap and pulls in no pydantic: the models live in
submodules (``shared_schema.constants``) and the error hierarchy in
``shared_schema.errors``, which ``solver_service.core`` may use without pydantic.
"""
