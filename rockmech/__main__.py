"""``python -m rockmech``: the ``rockmech`` command (``python -m rockmech --help``)."""

from solver_service.cli import main

if __name__ == "__main__":
    main()
