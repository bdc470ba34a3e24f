"""rockmech solver: the rocking equation of motion, its exact integration, and its interfaces.

``solver_service.core`` holds the pure numerics (no FastAPI, no pydantic, no Rhino);
``solver_service.cli`` is the ``rockmech`` command; ``solver_service.report`` draws plots.
"""
