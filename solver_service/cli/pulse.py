"""``rockmech pulse`` and ``rockmech boundary``: one mechanism under one-cycle pulses.

Each command imports its workflow when it runs: ``pulse`` loads the exact solver only
(``workflows.pulse``), not the envelopes, spectra or scipy.optimize of the other analyses.
"""

from __future__ import annotations

import gc
from pathlib import Path
from typing import Any, Optional

import typer

from ..core.kernel_cache import PLAIN_ETA_MAX, without_numba
from .app import CONSOLE
from .errors import fail, note, user_errors
from .options import JSON_OPT, SHAPES, criterion_opt
from .output import fmt_time, print_json

__all__ = ["boundary", "pulse"]


def _settles_fast(eta: Optional[float]) -> bool:
    """Whether a short-form pulse's rocking settles in few impacts (``PLAIN_ETA_MAX``).

    Without ``eta`` the request is refused (a pulse needs one, ``one_sided`` or not), which
    needs no kernel; the bound is on ``|eta|``, one-sided (``eta <= 0``) or two-sided; an
    ``eta`` outside [-1, 1] counts as slow (the solver refuses it).
    """
    return eta is None or bool(abs(eta) <= PLAIN_ETA_MAX)


@user_errors
def pulse(
    p_eq: Optional[float] = typer.Option(
        None, "--p-eq", help="Frequency parameter p_eq [rad/s] (or --constants)."
    ),
    lam: Optional[float] = typer.Option(
        None, "--lam", help="Static load multiplier lambda [-] (or --constants)."
    ),
    a_p_g: float = typer.Option(
        ...,
        "--a-p-g",
        help="Signed pulse amplitude [g]; > 0 first pushes towards negative "
        "rotation (Housner's convention), < 0 first opens the mechanism.",
    ),
    f_p: float = typer.Option(..., "--f-p", help="Pulse frequency [Hz]."),
    eta: Optional[float] = typer.Option(
        None, "--eta", help="Coefficient of restitution [-] (<= 0 one-sided)."
    ),
    one_sided: bool = typer.Option(False, "--one-sided", help="One-sided rocking."),
    phi_ov: Optional[float] = typer.Option(
        None, "--phi-ov", help="Overturning rotation [rad]; defaults to lambda."
    ),
    constants: Optional[Path] = typer.Option(
        None,
        "--constants",
        help="Kinematic-constants JSON: run one of its mechanisms (both sides, each impact "
        "direction's eta) instead of --p-eq, --lam, --eta, --phi-ov, --one-sided.",
    ),
    mechanism: Optional[str] = typer.Option(
        None, "--mechanism", help="Mechanism id in --constants (default: the first)."
    ),
    shape: str = typer.Option("sine", "--shape", metavar=SHAPES, help="Pulse shape."),
    criterion: Optional[str] = criterion_opt(
        "Overturning verdict: exact (default for pulses) or ratio."
    ),
    as_json: bool = JSON_OPT,
) -> None:
    """Response of one mechanism to a one-cycle sine or cosine acceleration pulse."""
    if CONSOLE["process"] and constants is None and _settles_fast(eta):
        # One pulse that settles in a few hundred impacts: the pure-Python kernels give the
        # compiled kernels' numbers in less time than numba takes to load (#38). The process
        # ends after it: no cyclic collection while the workflow's modules load (they hold
        # no garbage; a short pulse makes little).
        without_numba()
        gc.disable()
    # The pulse workflow (the exact solver) is loaded when the command runs (#38).
    from ..workflows import pulse as workflow

    request: dict[str, Any] = {"a_p_g": a_p_g, "f_p": f_p, "shape": shape}
    short = {"p_eq": p_eq, "lam": lam, "eta": eta, "phi_ov": phi_ov}
    request.update({k: v for k, v in short.items() if v is not None})
    request.update({"one_sided": True} if one_sided else {})
    request.update({"criterion": criterion} if criterion is not None else {})
    if constants is not None:
        # The constants reader is loaded only for --constants.
        from ..workflows.inputs import read_constants

        request["mechanism"] = workflow.pick_mechanism(read_constants(constants), mechanism)
    elif mechanism is not None:
        fail("mechanism: needs --constants (the file that holds it)")
    doc = workflow.solve_pulse(request)
    if as_json:
        print_json(doc)
        return
    verdict = "OVERTURNS" if doc.overturned else "survives"
    problem = doc.input
    name = f"{problem.mechanism}: " if problem.mechanism is not None else ""
    typer.echo(
        f"{name}Pulse {shape} a_p = {a_p_g:g} g, f_p = {f_p:g} Hz "
        f"(Omega = {problem.omega_ratio:.4g}, A = {problem.amplitude_ratio:.4g}):"
        f" {verdict} [{doc.criterion} criterion]"
    )
    typer.echo(
        f"  peak |phi|/phi_ov = {doc.peak_ratio:.6f} at {doc.t_peak:.4f} s "
        f"(error estimate {doc.error_estimate:.1e}); impacts: {doc.n_impacts}; "
        f"t_overturn: {fmt_time(doc.t_overturn)}"
    )
    for warning in doc.warnings:
        note(f"warning: {warning}")


@user_errors
def boundary(
    omega: float = typer.Option(..., "--omega", help="Frequency ratio omega_p / p_eq [-]."),
    eta: Optional[float] = typer.Option(
        None, "--eta", help="Coefficient of restitution [-] (one-sided: default 0)."
    ),
    one_sided: bool = typer.Option(False, "--one-sided", help="One-sided rocking."),
    shape: str = typer.Option("sine", "--shape", metavar=SHAPES, help="Pulse shape."),
    as_json: bool = JSON_OPT,
) -> None:
    """Every overturning interval in A = a_p/(g lam) at one frequency ratio (exact)."""
    # The documents (the overturning boundary) are loaded when the command runs.
    from ..workflows import documents

    doc = documents.boundary_doc(omega, eta, one_sided=one_sided, shape=shape)
    if as_json:
        print_json(doc)
        return
    spans = ", ".join(
        f"[{lo:.5g}, {'A_max' if hi is None else f'{hi:.5g}'}]"
        for lo, hi in doc.overturning_intervals
    )
    typer.echo(
        f"Omega = {omega:g}, eta = {doc.eta:g} ({doc.rocking}): "
        f"overturns for A in {spans or 'none'}"
    )
    typer.echo(f"  scan ratio {doc.search.scan_ratio:.4f}, bisection to {doc.search.rtol:g}")
