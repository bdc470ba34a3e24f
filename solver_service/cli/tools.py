"""``rockmech demo``, ``examples``, ``serve``, ``kernels`` and ``library build``.

The bundled example, the REST service, the compiled kernels and the overturning library:
each command imports what it runs when it runs.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Optional

import typer

from shared_schema.extras import require
from shared_schema.version import __version__

from ..workflows.rundir import check_file_target, run_folder
from .errors import fail, note, user_errors
from .output import g4, out_note, table

__all__ = ["demo", "examples", "kernels", "library_app", "library_build", "serve"]

library_app = typer.Typer(help="The library of dimensionless overturning curves.")


@user_errors
def library_build(
    out: Optional[Path] = typer.Option(
        None,
        "--out",
        help=(
            "Output .npz (default: the user's cache folder, which envelopes read before the "
            "shipped library; the installed package is never written)."
        ),
    ),
    n_omega: int = typer.Option(533, "--n-omega", help="Omega points, log-spaced in [0.05, 500]."),
    eta_step: float = typer.Option(0.02, "--eta-step", help="Step of eta in [0, 1]."),
) -> None:
    """Compute A_min(Omega; eta) for eta in [0, 1] and the one-sided curve (about 4 s)."""
    import numpy as np
    from rich.console import Console
    from rich.progress import Progress

    # The envelopes' library is loaded when the command runs (#38).
    from ..core.envelope import LIBRARY_OMEGA, LIBRARY_PATH, build_library, user_library_path

    target = out if out is not None else user_library_path()
    if target is None:
        fail("out: no user cache folder here (platformdirs is missing); give --out FILE")
    check_file_target(target)
    if n_omega < 2:
        fail(f"n_omega: must be >= 2, got {n_omega}")
    if not 0.0 < eta_step <= 1.0:
        fail(f"eta_step: must be in (0, 1], got {eta_step}")
    omega = np.geomspace(LIBRARY_OMEGA[0], LIBRARY_OMEGA[1], n_omega)
    eta = np.unique(np.append(np.round(np.arange(0.0, 1.0, eta_step), 12), 1.0))

    # Progress on stderr, and only on a terminal.
    console = Console(stderr=True)
    with Progress(transient=True, console=console, disable=not console.is_terminal) as bar:
        task = bar.add_task("overturning curves", total=None)

        def tick(done: int, total: int) -> None:
            bar.update(task, completed=done, total=total)

        lib = build_library(omega=omega, eta=eta, progress=tick)
    path = lib.save(target)
    typer.echo(
        f"wrote {path}: {lib.eta.size} two-sided curves + one-sided, {lib.omega.size} Omega, "
        f"{lib.metadata['build_seconds']} s"
    )
    if out is None:
        typer.echo(
            "  envelopes now read it instead of the shipped library (their method names it); "
            f"delete it to go back to {LIBRARY_PATH.name}"
        )


@user_errors
def demo(
    out: Path = typer.Option(Path("out"), "--out", help="Output folder."),
    record: Optional[Path] = typer.Option(
        None, "--record", help="Two-column record in g (default: bundled El Centro 1940 N-S)."
    ),
) -> None:
    """Run the bundled example: rectangular walls on El Centro 1940, exact integration."""
    # The demo's analyses are loaded when the command runs (#38).
    from ..demo import run_demo

    with run_folder(out, on_note=out_note, command="demo") as tmp:
        written = run_demo(tmp, record, on_skip=lambda text: note(f"note: {text}"))
    paths = {kind: out / path.relative_to(tmp) for kind, path in written.items()}
    for kind, path in paths.items():
        typer.echo(f"wrote {kind}: {path}")
    summary = json.loads(paths["history"].read_text())
    rows = [
        [
            str(row["mechanism"]),
            g4(row["scale"]),
            g4(row["peak_ratio"]),
            "OVERTURNS" if row["overturned"] else "survives",
        ]
        for row in summary["results"]
    ]
    for line in table(["mechanism", "scale", "peak |phi|/phi_ov", "verdict"], rows):
        typer.echo(line)


@user_errors
def examples(
    out: Path = typer.Argument(
        Path("examples"), help="Folder to copy the examples into (default: ./examples)."
    ),
) -> None:
    """Copy the bundled examples (scenes, specs, constants, records, sites) into a folder.

    The README's commands use examples/... paths: run them from the folder holding OUT.
    Only files an earlier copy wrote are replaced; your own files there are never touched.
    """
    # The examples' copier lives with the demo, loaded when the command runs.
    from ..demo import copy_examples

    written = copy_examples(out, on_note=out_note)
    typer.echo(f"wrote {len(written)} example files to {out}")


@user_errors
def serve(
    host: Optional[str] = typer.Option(
        None, "--host", help="Interface to bind (default 127.0.0.1: this machine only)."
    ),
    port: Optional[int] = typer.Option(None, "--port", help="TCP port (default 8000)."),
    workers: Optional[int] = typer.Option(None, "--workers", help="Compute processes (default 2)."),
    timeout: Optional[float] = typer.Option(
        None, "--timeout", help="Compute time budget per request [s] (default 30)."
    ),
) -> None:
    """Run the REST service (FastAPI + uvicorn); settings also from ROCKMECH_* variables."""
    for module in ("fastapi", "uvicorn", "pydantic_settings"):
        require(module, "service", "for rockmech serve")
    # The service extra is loaded only by the command that needs it.
    from ..api.server import run, settings_with

    settings = settings_with(
        host=host, port=port, compute_workers=workers, compute_timeout_s=timeout
    )
    _kernels_ahead()
    host_part = f"[{settings.host}]" if ":" in settings.host else settings.host
    typer.echo(f"rockmech {__version__} serving on http://{host_part}:{settings.port}")
    typer.echo(f"  docs: http://{host_part}:{settings.port}/api/v1/docs (Ctrl+C to stop)")
    run(settings)


def _kernels_ahead() -> None:
    """Compile the kernels once, in a child process, before the workers start (#28).

    Each worker then loads them from numba's cache in under a second, instead of every
    worker compiling them at once at start-up. The child prints a progress line only when it
    compiles.
    """
    code = "import sys; from solver_service.core.precompile import main; sys.exit(main())"
    subprocess.run([sys.executable, "-c", code], check=False)


@user_errors
def kernels() -> None:
    """Compile the solver's kernels now (numba), so that no later run waits for it."""
    # numba and the kernels are loaded when the command runs (#38).
    from ..core.jit import PATHS, kernel_status

    # The ahead-of-time build of every path.
    from ..core.precompile import build as build_kernels

    status = kernel_status()
    if status.active and len(status.built) < len(PATHS):
        status = build_kernels()
    typer.echo(status.describe())
