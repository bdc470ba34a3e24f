"""Shared constants of the numerics report (``docs/numerics.md``, issue 7).

Each numerics script owns one section of ``docs/numerics.md`` between the markers
``<!-- BEGIN <name> -->`` and ``<!-- END <name> -->`` and rewrites only that section with
``_docs.write_section(DOC_MD, name, text, header=HEADER)``.
"""

from __future__ import annotations

from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
#: The numerics report.
DOC_MD = REPO / "docs" / "numerics.md"
#: Folder of its figures.
IMG = REPO / "docs" / "img"
#: Title and paragraph at the top of ``DOC_MD``.
HEADER = (
    "# Numerics: error against run time, and stability on stiff and extreme cases\n"
    "\n"
    "How accurate every integrator in rockmech is, what it costs, and whether any corner of "
    "parameter space breaks it. Every section below is produced by the command it names "
    "(all of them by `make numerics`) and rewrites only that section; the figures are the "
    "latest run on the machine it describes.\n"
)
