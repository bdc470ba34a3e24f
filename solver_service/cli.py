"""The ``rockmech`` command line.

Every command validates its inputs up front; a bad argument exits with status 2 and a
one-line reason on stderr (``error: <field>: <what is wrong>``). With ``--json`` a command
prints exactly one JSON document to stdout. SI units throughout, except where an option
name says otherwise (``--a-p-g`` is in g).
"""

from __future__ import annotations

import functools
import json
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any, NoReturn, Optional, TypeVar

import typer

from shared_schema.errors import RockmechError

app = typer.Typer(
    name="rockmech",
    help="Rocking collapse mechanisms of masonry: exact rocking solver and tools (SI units).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)

F = TypeVar("F", bound=Callable[..., Any])


def _fail(message: str) -> NoReturn:
    typer.echo(f"error: {message}", err=True)
    raise typer.Exit(code=2)


def _user_errors(fn: F) -> F:
    """Turn rockmech's own errors into a one-line message and exit status 2."""

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            return fn(*args, **kwargs)
        except RockmechError as exc:
            _fail(str(exc))

    return wrapper  # type: ignore[return-value]


def _json_default(value: Any) -> Any:
    if isinstance(value, float) and not math.isfinite(value):
        return None
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")


def _print_json(doc: Any) -> None:
    typer.echo(json.dumps(doc, indent=2, default=_json_default, allow_nan=False))


def _fmt_time(value: Optional[float]) -> str:
    return "-" if value is None else f"{value:.4f} s"


@app.command()
@_user_errors
def pulse(
    p_eq: float = typer.Option(..., "--p-eq", help="Frequency parameter p_eq [rad/s]."),
    lam: float = typer.Option(..., "--lam", help="Static load multiplier lambda [-]."),
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
    shape: str = typer.Option("sine", "--shape", help="Pulse shape: sine or cosine."),
    criterion: Optional[str] = typer.Option(
        None, "--criterion", help="Overturning verdict: exact (default for pulses) or ratio."
    ),
    as_json: bool = typer.Option(False, "--json", help="Print one JSON document."),
) -> None:
    """Response of one mechanism to a one-cycle sine or cosine acceleration pulse."""
    from .core.exact import simulate
    from .core.excitation import Pulse
    from .core.model import G, RockingModel

    model = RockingModel.symmetric(p_eq, lam, eta, phi_ov=phi_ov, one_sided=one_sided, name="pulse")
    model.require_eta()
    exc = Pulse(a_p=a_p_g * G, f_p=f_p, shape=shape)
    res = simulate(model, exc, criterion=criterion)
    doc = {
        "input": {
            "p_eq": p_eq,
            "lam": lam,
            "phi_ov": model.positive.phi_ov,
            "eta": eta,
            "rocking": "one_sided" if one_sided else "two_sided",
            "a_p_g": a_p_g,
            "f_p": f_p,
            "shape": shape,
            "omega_ratio": exc.omega_p / p_eq,
            "amplitude_ratio": abs(a_p_g) / lam,
            "pulse_convention": "A (Zhang & Makris 2001: pulse starts at t = 0)",
        },
        **res.summary(),
    }
    if as_json:
        _print_json(doc)
        return
    verdict = "OVERTURNS" if res.overturned else "survives"
    typer.echo(
        f"Pulse {shape} a_p = {a_p_g:g} g, f_p = {f_p:g} Hz "
        f"(Omega = {exc.omega_p / p_eq:.4g}, A = {abs(a_p_g) / lam:.4g}): {verdict} "
        f"[{res.criterion} criterion]"
    )
    typer.echo(
        f"  peak |phi|/phi_ov = {res.peak_ratio:.6f} at {res.t_peak:.4f} s "
        f"(error estimate {res.error_estimate:.1e}); impacts: {res.n_impacts}; "
        f"t_overturn: {_fmt_time(res.t_overturn)}"
    )


@app.command(context_settings={"allow_extra_args": True, "ignore_unknown_options": True})
@_user_errors
def history(
    ctx: typer.Context,
    constants: Path = typer.Argument(..., help="Kinematic-constants JSON file."),
    record: Path = typer.Argument(
        ..., help="Record file: PEER AT2, two columns (t, a), one column (with --dt) or CSV."
    ),
    scale: list[float] = typer.Option(
        [1.0], "--scale", help="Scale factors on the record, e.g. --scale 0.5 1 2."
    ),
    units: Optional[str] = typer.Option(
        None,
        "--units",
        help="Acceleration units: g, m/s2 or cm/s2; AT2 files state their own, two-column "
        "files default to g, other formats need it.",
    ),
    record_format: Optional[str] = typer.Option(
        None, "--format", help="at2, two_column, one_column or csv (default: detected)."
    ),
    dt: Optional[float] = typer.Option(
        None, "--dt", help="Time step [s] of a record without a time column."
    ),
    sf: str = typer.Option(
        "none",
        "--sf",
        help="Scale factor up the structure for mechanisms with amplification data: none, or "
        "eq28 (from the record's 5 % spectrum at T_n = 1/f_n).",
    ),
    criterion: Optional[str] = typer.Option(
        None, "--criterion", help="Overturning verdict: ratio (default for records) or exact."
    ),
    out: Optional[Path] = typer.Option(
        None, "--out", help="Folder for history.json and a time-history plot."
    ),
    as_json: bool = typer.Option(False, "--json", help="Print one JSON document."),
) -> None:
    """Time history of every mechanism in CONSTANTS under RECORD at each scale factor."""
    from shared_schema.io import load_constants, write_atomic

    from .adapter import models_from_file
    from .analysis import history_doc
    from .core.records import GroundMotion, detect_format

    scales = list(scale)
    for extra in ctx.args:
        try:
            scales.append(float(extra))
        except ValueError:
            _fail(f"unexpected argument {extra!r}")
    if not constants.is_file():
        _fail(f"constants: file not found: {constants}")
    cf = load_constants(constants)
    models = models_from_file(cf)
    fmt = record_format or detect_format(record)
    if units is None and fmt == "two_column":
        units = "g"  # the two-column t [s], a [g] convention of the bundled record
    motion = GroundMotion.from_file(record, format=fmt, units=units, dt=dt)
    doc = history_doc(cf, motion, scales, sf=sf, criterion=criterion)
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
        write_atomic(out / "history.json", json.dumps(doc, indent=2) + "\n")
        _history_plot(models, motion, max(scales), out / "history.png")
    if as_json:
        _print_json(doc)
        return
    typer.echo(
        f"{motion.name}: PGA {motion.pga_g:.3f} g, dt {motion.dt:g} s, "
        f"{motion.duration:.2f} s; criterion: {doc['criterion']}"
    )
    typer.echo(
        f"{'mechanism':<16}{'scale':>8}{'peak':>10}{'overturned':>12}"
        f"{'t_ov [s]':>10}{'impacts':>9}{'error':>10}"
    )
    for row in doc["results"]:
        t_ov = "-" if row["t_overturn"] is None else f"{row['t_overturn']:.3f}"
        typer.echo(
            f"{row['mechanism']:<16}{row['scale']:>8g}{row['peak_ratio']:>10.4f}"
            f"{'yes' if row['overturned'] else 'no':>12}{t_ov:>10}{row['n_impacts']:>9}"
            f"{row['error_estimate']:>10.1e}"
        )


def _history_plot(models: list[Any], motion: Any, scale: float, path: Path) -> None:
    from .core.exact import simulate
    from .core.model import G
    from .report.plots import plot_time_histories

    runs = [(m.name, simulate(m, motion.accel, scale=scale, dense=True)) for m in models]
    plot_time_histories(
        runs,
        path,
        record_t=motion.accel.time,
        record_a_g=scale * motion.accel.acc / G,
        title=f"{motion.name} x {scale:g}",
    )


@app.command()
@_user_errors
def constants(
    scene: Path = typer.Argument(..., help="Rhino .3dm file."),
    spec: Path = typer.Argument(..., help="Mechanism spec (JSON)."),
    output: Path = typer.Option(..., "-o", "--output", help="Kinematic-constants JSON to write."),
    as_json: bool = typer.Option(False, "--json", help="Also print the constants JSON."),
) -> None:
    """Kinematic constants of every mechanism in SPEC from the solids of SCENE."""
    from rhino_plugin.mechanisms.build import constants_from_spec
    from rhino_plugin.scene_3dm import Scene
    from shared_schema.io import save_constants
    from shared_schema.spec import parse_spec

    for label, path in (("scene", scene), ("spec", spec)):
        if not path.is_file():
            _fail(f"{label}: file not found: {path}")
    spec_file = parse_spec(spec.read_bytes(), spec.name)
    cf = constants_from_spec(
        spec_file,
        Scene.from_3dm(scene),
        scene_name=scene.name,
        spec_name=spec.name,
        spec_dir=spec.parent,
    )
    save_constants(output, cf)
    if as_json:
        _print_json(json.loads(cf.model_dump_json(exclude_none=True)))
        return
    typer.echo(f"wrote {output}")
    for m in cf.mechanisms:
        side = m.positive
        typer.echo(
            f"  {m.id:<8} p_eq = {side.p_eq:.4f} rad/s  lam = {side.lam:.4f}  "
            f"phi_ov = {side.phi_ov:.4f} rad  eta = {m.eta if m.eta is not None else '-'}"
        )
        notes = (m.provenance or {}).get("warnings") or []
        for note in notes if isinstance(notes, list) else []:
            typer.echo(f"    warning: {note}")


@app.command()
@_user_errors
def envelope(
    constants: Path = typer.Argument(..., help="Kinematic-constants JSON file."),
    out: Path = typer.Option(..., "--out", help="Folder for envelope.json, .csv and .png."),
    f_min: float = typer.Option(0.1, "--f-min", help="Lowest pulse frequency [Hz]."),
    f_max: float = typer.Option(10.0, "--f-max", help="Highest pulse frequency [Hz]."),
    n: int = typer.Option(200, "--n", help="Number of log-spaced frequencies."),
    exact: bool = typer.Option(
        False, "--exact", help="Compute boundaries directly instead of from the library."
    ),
    as_json: bool = typer.Option(False, "--json", help="Also print the JSON document."),
) -> None:
    """Minimum overturning sine-pulse amplitude of every mechanism, and the critical bands."""
    from shared_schema.io import load_constants

    from .analysis import frequency_grid, write_envelope

    f_p = frequency_grid(f_min, f_max, n)
    if not constants.is_file():
        _fail(f"constants: file not found: {constants}")
    cf = load_constants(constants)
    doc = write_envelope(
        cf, f_p, out, exact=exact, title=f"Overturning envelopes: {constants.name}"
    )
    if as_json:
        _print_json(doc)
        return
    typer.echo(f"wrote {out / 'envelope.json'}, envelope.csv, envelope.png")
    typer.echo("critical mechanism by pulse frequency:")
    for band in doc["critical"]:
        typer.echo(f"  {band['f_min']:8.3f} - {band['f_max']:8.3f} Hz: {band['mechanism']}")


@app.command()
@_user_errors
def boundary(
    omega: float = typer.Option(..., "--omega", help="Frequency ratio omega_p / p_eq [-]."),
    eta: Optional[float] = typer.Option(
        None, "--eta", help="Coefficient of restitution [-] (one-sided: default 0)."
    ),
    one_sided: bool = typer.Option(False, "--one-sided", help="One-sided rocking."),
    shape: str = typer.Option("sine", "--shape", help="Pulse shape: sine or cosine."),
    as_json: bool = typer.Option(False, "--json", help="Print one JSON document."),
) -> None:
    """Every overturning interval in A = a_p/(g lam) at one frequency ratio (exact)."""
    from .analysis import boundary_doc

    doc = boundary_doc(omega, eta, one_sided=one_sided, shape=shape)
    if as_json:
        _print_json(doc)
        return
    spans = ", ".join(
        f"[{lo:.5g}, {'A_max' if hi is None else f'{hi:.5g}'}]"
        for lo, hi in doc["overturning_intervals"]
    )
    typer.echo(
        f"Omega = {omega:g}, eta = {doc['eta']:g} ({doc['rocking']}): "
        f"overturns for A in {spans or 'none'}"
    )
    typer.echo(
        f"  scan ratio {doc['search']['scan_ratio']:.4f}, bisection to {doc['search']['rtol']:g}"
    )


library_app = typer.Typer(help="The library of dimensionless overturning curves.")
app.add_typer(library_app, name="library")


@library_app.command("build")
@_user_errors
def library_build(
    out: Optional[Path] = typer.Option(
        None, "--out", help="Output .npz (default: the package's shipped library)."
    ),
    n_omega: int = typer.Option(400, "--n-omega", help="Omega points, log-spaced in [0.05, 50]."),
    eta_step: float = typer.Option(0.02, "--eta-step", help="Step of eta in [0, 1]."),
) -> None:
    """Compute A_min(Omega; eta) for eta in [0, 1] and the one-sided curve (about a minute)."""
    import numpy as np
    from rich.progress import Progress

    from .core.envelope import LIBRARY_OMEGA, LIBRARY_PATH, build_library

    if n_omega < 2:
        _fail(f"n_omega: must be >= 2, got {n_omega}")
    if not 0.0 < eta_step <= 1.0:
        _fail(f"eta_step: must be in (0, 1], got {eta_step}")
    omega = np.geomspace(LIBRARY_OMEGA[0], LIBRARY_OMEGA[1], n_omega)
    eta = np.unique(np.append(np.round(np.arange(0.0, 1.0, eta_step), 12), 1.0))

    with Progress(transient=True) as bar:
        task = bar.add_task("overturning curves", total=None)

        def tick(done: int, total: int) -> None:
            bar.update(task, completed=done, total=total)

        lib = build_library(omega=omega, eta=eta, progress=tick)
    path = lib.save(out or LIBRARY_PATH)
    typer.echo(
        f"wrote {path}: {lib.eta.size} two-sided curves + one-sided, {lib.omega.size} Omega, "
        f"{lib.metadata['build_seconds']} s"
    )


@app.command()
@_user_errors
def demo(
    out: Path = typer.Option(Path("out"), "--out", help="Output folder."),
    record: Optional[Path] = typer.Option(
        None, "--record", help="Two-column record in g (default: bundled El Centro 1940 N-S)."
    ),
) -> None:
    """Run the bundled example: rectangular walls on El Centro 1940, exact integration."""
    from .demo import run_demo

    paths = run_demo(out, record)
    for kind, path in paths.items():
        typer.echo(f"wrote {kind}: {path}")
    summary = json.loads(paths["history"].read_text())
    for row in summary["results"]:
        typer.echo(
            f"  {row['mechanism']:<8} x{row['scale']:<4g} peak |phi|/phi_ov = "
            f"{row['peak_ratio']:.4f}  {'OVERTURNS' if row['overturned'] else 'survives'}"
        )


def main() -> None:  # pragma: no cover - console entry point
    """Entry point of the ``rockmech`` console script."""
    app()
