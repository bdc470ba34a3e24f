"""The ``rockmech`` command line.

Every command validates its inputs up front; a bad argument exits with status 2 and a
one-line reason on stderr (``error: <field>: <what is wrong>``). With ``--json`` a command
prints exactly one JSON document to stdout. SI units throughout, except where an option
name says otherwise (``--a-p-g`` is in g).
"""

from __future__ import annotations

import functools
import json
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


def _print_json(doc: Any) -> None:
    from .analysis import finite_json

    typer.echo(json.dumps(finite_json(doc), indent=2, allow_nan=False))


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
    from .analysis import pulse_doc

    doc = pulse_doc(
        p_eq,
        lam,
        a_p_g,
        f_p,
        eta=eta,
        one_sided=one_sided,
        phi_ov=phi_ov,
        shape=shape,
        criterion=criterion,
    )
    if as_json:
        _print_json(doc)
        return
    verdict = "OVERTURNS" if doc["overturned"] else "survives"
    typer.echo(
        f"Pulse {shape} a_p = {a_p_g:g} g, f_p = {f_p:g} Hz "
        f"(Omega = {doc['input']['omega_ratio']:.4g}, A = {doc['input']['amplitude_ratio']:.4g}):"
        f" {verdict} [{doc['criterion']} criterion]"
    )
    typer.echo(
        f"  peak |phi|/phi_ov = {doc['peak_ratio']:.6f} at {doc['t_peak']:.4f} s "
        f"(error estimate {doc['error_estimate']:.1e}); impacts: {doc['n_impacts']}; "
        f"t_overturn: {_fmt_time(doc['t_overturn'])}"
    )
    for note in doc["warnings"]:
        typer.echo(f"warning: {note}", err=True)


# Options shared by every command that reads a ground-motion record.
_RECORD_ARG = typer.Argument(
    ..., help="Record file: PEER AT2, two columns (t, a), one column (with --dt) or CSV."
)
_UNITS_OPT = typer.Option(
    None,
    "--units",
    help="Acceleration units: g, m/s2 or cm/s2; AT2 files state their own, two-column "
    "files default to g, other formats need it.",
)
_FORMAT_OPT = typer.Option(
    None, "--format", help="at2, two_column, one_column or csv (default: detected)."
)
_DT_OPT = typer.Option(None, "--dt", help="Time step [s] of a record without a time column.")
# Options of the scale factor up the structure (history, ida, report).
_SF_OPT = typer.Option(
    "none",
    "--sf",
    help="Scale factor up the structure for mechanisms with amplification data: none; "
    "eq28 (from the record's 5 % spectrum at T_n = 1/f_n); ec8 (EN 1998-1 §4.3.5.2, "
    "needs --building-height); nzs (NZS 1170.5 C_Hi, needs --building-height).",
)
_BUILDING_HEIGHT_OPT = typer.Option(
    None, "--building-height", help="Height of the building H = h_n [m] (ec8, nzs)."
)
_SOIL_FACTOR_OPT = typer.Option(1.0, "--soil-factor", help="EC8 soil factor S [-].")
_ELEMENT_PERIOD_OPT = typer.Option(
    0.0, "--element-period", help="EC8 period of the element T_a [s]; 0 = rigid."
)


def _read_record(path: Path, fmt: Optional[str], units: Optional[str], dt: Optional[float]) -> Any:
    from .analysis import read_record

    return read_record(path, fmt, units, dt)


def _read_constants(path: Path) -> Any:
    from shared_schema.io import load_constants

    if not path.is_file():
        _fail(f"constants: file not found: {path}")
    return load_constants(path)


def _scales(first: list[float], extra: list[str]) -> list[float]:
    """Collect the --scale values, also those typed after the first (``--scale 0.5 1 2``)."""
    scales = list(first)
    for token in extra:
        try:
            scales.append(float(token))
        except ValueError:
            _fail(f"unexpected argument {token!r}")
    return scales


@app.command(context_settings={"allow_extra_args": True, "ignore_unknown_options": True})
@_user_errors
def history(
    ctx: typer.Context,
    constants: Path = typer.Argument(..., help="Kinematic-constants JSON file."),
    record: Path = _RECORD_ARG,
    scale: list[float] = typer.Option(
        [1.0], "--scale", help="Scale factors on the record, e.g. --scale 0.5 1 2."
    ),
    units: Optional[str] = _UNITS_OPT,
    record_format: Optional[str] = _FORMAT_OPT,
    dt: Optional[float] = _DT_OPT,
    sf: str = _SF_OPT,
    building_height: Optional[float] = _BUILDING_HEIGHT_OPT,
    soil_factor: float = _SOIL_FACTOR_OPT,
    element_period: float = _ELEMENT_PERIOD_OPT,
    at_height: Optional[float] = typer.Option(
        None,
        "--at-height",
        help="Also report the peak displacement [m] of a point this far [m] above each "
        "mechanism's rotation axis (to compare with shake-table tests).",
    ),
    criterion: Optional[str] = typer.Option(
        None, "--criterion", help="Overturning verdict: ratio (default for records) or exact."
    ),
    out: Optional[Path] = typer.Option(
        None,
        "--out",
        help="Folder for history.json, history.png (phi/phi_ov per scale) and "
        "history_record.png (record, largest pulse and spectrum).",
    ),
    as_json: bool = typer.Option(False, "--json", help="Print one JSON document."),
) -> None:
    """Time history of every mechanism in CONSTANTS under RECORD at each scale factor."""
    from .analysis import Building, history_doc, write_history

    scales = _scales(scale, ctx.args)
    cf = _read_constants(constants)
    motion = _read_record(record, record_format, units, dt)
    options: dict[str, Any] = {
        "sf": sf,
        "building": Building(building_height, soil_factor, element_period),
        "criterion": criterion,
        "at_height": at_height,
    }
    if out is not None:
        doc = write_history(cf, motion, scales, out, **options)
    else:
        doc = history_doc(cf, motion, scales, **options)
    if as_json:
        _print_json(doc)
        return
    typer.echo(
        f"{motion.name}: PGA {motion.pga_g:.3f} g, dt {motion.dt:g} s, "
        f"{motion.duration:.2f} s; criterion: {doc['criterion']}"
    )
    for mech_id, info in doc.get("scale_factors", {}).items():
        typer.echo(f"  SF {mech_id}: {info['value']:.4f} = {info['formula']}")
    disp = at_height is not None
    typer.echo(
        f"{'mechanism':<16}{'scale':>8}{'peak':>10}{'overturned':>12}"
        f"{'t_ov [s]':>10}{'impacts':>9}{'error':>10}" + (f"{'u_peak [m]':>12}" if disp else "")
    )
    for row in doc["results"]:
        t_ov = "-" if row["t_overturn"] is None else f"{row['t_overturn']:.3f}"
        typer.echo(
            f"{row['mechanism']:<16}{row['scale']:>8g}{row['peak_ratio']:>10.4f}"
            f"{'yes' if row['overturned'] else 'no':>12}{t_ov:>10}{row['n_impacts']:>9}"
            f"{row['error_estimate']:>10.1e}"
            + (f"{row['peak_displacement_m']:>12.4g}" if disp else "")
        )
    for mech_id, notes in doc.get("warnings", {}).items():
        for note in notes:
            typer.echo(f"warning: {mech_id}: {note}", err=True)
    if out is not None:
        typer.echo(f"wrote {out / 'history.json'}, history.png, history_record.png")


@app.command("record")
@_user_errors
def record_info(
    record: Path = _RECORD_ARG,
    units: Optional[str] = _UNITS_OPT,
    record_format: Optional[str] = _FORMAT_OPT,
    dt: Optional[float] = _DT_OPT,
    zeta: float = typer.Option(0.05, "--damping", help="Damping ratio of the spectrum [-]."),
    t_min: float = typer.Option(0.02, "--t-min", help="Shortest period of the spectrum [s]."),
    t_max: float = typer.Option(10.0, "--t-max", help="Longest period of the spectrum [s]."),
    n: int = typer.Option(100, "--n", help="Number of log-spaced periods."),
    pulses: int = typer.Option(5, "--pulses", help="How many of the largest pulses to list."),
    f_min: Optional[float] = typer.Option(None, "--f-min", help="Pulse search: lowest f_p [Hz]."),
    f_max: Optional[float] = typer.Option(None, "--f-max", help="Pulse search: highest f_p [Hz]."),
    out: Optional[Path] = typer.Option(
        None, "--out", help="Folder for record.json and record.png (record and spectrum)."
    ),
    as_json: bool = typer.Option(False, "--json", help="Print one JSON document."),
) -> None:
    """Describe a record: metadata, largest sine pulses and exact response spectrum."""
    from .analysis import log_grid, record_doc
    from .core.pulses import extract_pulses
    from .core.spectra import response_spectrum

    motion = _read_record(record, record_format, units, dt)
    periods = log_grid(t_min, t_max, n, names=("t_min", "t_max"))
    found = extract_pulses(motion.accel, f_min=f_min, f_max=f_max, n=pulses)
    spectrum = response_spectrum(motion.accel.acc, motion.dt, periods, zeta)
    doc = record_doc(motion, spectrum, found)
    if out is not None:
        from shared_schema.io import write_atomic

        from .report.plots import plot_record

        out.mkdir(parents=True, exist_ok=True)
        write_atomic(out / "record.json", json.dumps(doc, indent=2) + "\n")
        plot_record(motion, out / "record.png", spectrum=spectrum, pulses=found)
    if as_json:
        _print_json(doc)
        return
    typer.echo(
        f"{motion.name}: {len(motion.accel.acc)} samples, dt {motion.dt:g} s, "
        f"{motion.duration:.2f} s, PGA {motion.pga_g:.4f} g"
    )
    typer.echo("largest one-cycle sine pulses (a_p signed: > 0 first accelerates positively):")
    for p in doc["pulses"]:
        typer.echo(
            f"  a_p = {p['a_p_g']:+.4f} g  f_p = {p['f_p_hz']:.3f} Hz  t = {p['t_start_s']:.3f} s"
        )
    spec = doc["spectrum"]
    k = max(range(len(spec["psa_g"])), key=lambda i: spec["psa_g"][i])
    typer.echo(
        f"spectrum ({100 * zeta:g} %): peak PSA {spec['psa_g'][k]:.4f} g at "
        f"T = {spec['periods_s'][k]:.3f} s ({spec['runtime_s'] * 1e3:.1f} ms)"
    )
    if out is not None:
        typer.echo(f"wrote {out / 'record.json'}, record.png")


@app.command()
@_user_errors
def ida(
    constants: Path = typer.Argument(..., help="Kinematic-constants JSON file."),
    records: list[Path] = typer.Argument(..., help="Record files (any supported format)."),
    scales: str = typer.Option(
        ...,
        "--scales",
        help="Intensity levels: a list 0.25,0.5,1,2 or a log range start:stop:n (0.1:3:20).",
    ),
    im: str = typer.Option(
        "scale", "--im", help="Intensity measure: scale (factor on each record) or pga [g]."
    ),
    units: Optional[str] = _UNITS_OPT,
    record_format: Optional[str] = _FORMAT_OPT,
    dt: Optional[float] = _DT_OPT,
    sf: str = _SF_OPT,
    building_height: Optional[float] = _BUILDING_HEIGHT_OPT,
    soil_factor: float = _SOIL_FACTOR_OPT,
    element_period: float = _ELEMENT_PERIOD_OPT,
    criterion: Optional[str] = typer.Option(
        None, "--criterion", help="Overturning verdict: ratio (default) or exact."
    ),
    scheduler: Optional[str] = typer.Option(
        None,
        "--scheduler",
        help="dask.distributed scheduler address (tcp://host:8786); default: run locally.",
    ),
    timeout: float = typer.Option(
        10.0, "--timeout", help="Seconds to wait for the Dask scheduler to answer [s]."
    ),
    progress: Optional[bool] = typer.Option(
        None, "--progress/--no-progress", help="Progress bar (default: on a terminal)."
    ),
    out: Optional[Path] = typer.Option(
        None, "--out", help="Folder for ida.json, ida.csv and ida.png (fragility curves)."
    ),
    as_json: bool = typer.Option(False, "--json", help="Print one JSON document."),
) -> None:
    """Incremental dynamic analysis: overturned fraction per intensity and fragility fits."""
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TimeElapsedColumn

    from .analysis import Building
    from .core.model import check_positive
    from .ida import ida_csv, parse_levels, run_ida

    levels = parse_levels(scales)
    cf = _read_constants(constants)
    motions = [_read_record(path, record_format, units, dt) for path in records]
    console = Console(stderr=True)
    show = console.is_terminal if progress is None else progress
    bar = Progress(
        "[progress.description]{task.description}",
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        console=console,
        disable=not show,
        transient=True,
    )
    with bar:
        task = bar.add_task("records", total=len(motions))
        doc = run_ida(
            cf,
            motions,
            levels,
            im=im,
            sf=sf,
            building=Building(building_height, soil_factor, element_period),
            criterion=criterion,
            scheduler=scheduler,
            progress=lambda done, total: bar.update(task, completed=done),
            timeout=check_positive(timeout, "timeout"),
        )
    if out is not None:
        from shared_schema.io import write_atomic

        from .report.plots import plot_fragility

        out.mkdir(parents=True, exist_ok=True)
        write_atomic(out / "ida.json", json.dumps(doc, indent=2) + "\n")
        write_atomic(out / "ida.csv", ida_csv(doc))
        plot_fragility(doc, out / "ida.png", title=f"Fragility: {constants.name}")
    if as_json:
        _print_json(doc)
        return
    backend = doc["backend"]
    where = "locally" if backend["kind"] == "local" else f"on Dask at {backend['scheduler']}"
    typer.echo(
        f"{doc['runs']} runs ({len(motions)} records x {len(levels)} levels x "
        f"{len(cf.mechanisms)} mechanisms) {where} in {doc['runtime_s']:.2f} s; "
        f"largest error estimate {doc['max_error_estimate']:.1e}"
    )
    unit = doc["intensity"]["units"]
    for mech in doc["mechanisms"]:
        fit = mech["fragility"]
        if "median" in fit:
            text = f"median {fit['median']:.4g} {unit}, beta {fit['beta']:.3f}"
        else:
            text = "no fit"
        note = f" ({fit['note']})" if "note" in fit else ""
        typer.echo(f"  {mech['id']:<12} {text}{note}")
    if out is not None:
        typer.echo(f"wrote {out / 'ida.json'}, ida.csv, ida.png")


@app.command()
@_user_errors
def constants(
    scene: Path = typer.Argument(..., help="Rhino .3dm file, or a scan mesh .ply/.obj/.stl/.off."),
    spec: Path = typer.Argument(..., help="Mechanism spec (JSON)."),
    output: Path = typer.Option(..., "-o", "--output", help="Kinematic-constants JSON to write."),
    as_json: bool = typer.Option(False, "--json", help="Also print the constants JSON."),
    units: Optional[str] = typer.Option(
        None, "--units", help="Length unit of a scan mesh: mm, cm, m, in or ft (required there)."
    ),
) -> None:
    """Kinematic constants of every mechanism in SPEC from the solids of SCENE."""
    from rhino_plugin.mechanisms.build import constants_from_spec
    from rhino_plugin.scenes import read_scene
    from shared_schema.io import save_constants
    from shared_schema.spec import parse_spec

    for label, path in (("scene", scene), ("spec", spec)):
        if not path.is_file():
            _fail(f"{label}: file not found: {path}")
    spec_file = parse_spec(spec.read_bytes(), spec.name)
    cf = constants_from_spec(
        spec_file,
        read_scene(scene, units=units),
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


@app.command(context_settings={"allow_extra_args": True, "ignore_unknown_options": True})
@_user_errors
def envelope(
    ctx: typer.Context,
    constants: Path = typer.Argument(..., help="Kinematic-constants JSON file."),
    out: Path = typer.Option(..., "--out", help="Folder for envelope.json, .csv and .png."),
    f_min: float = typer.Option(0.1, "--f-min", help="Lowest pulse frequency [Hz]."),
    f_max: float = typer.Option(10.0, "--f-max", help="Highest pulse frequency [Hz]."),
    n: int = typer.Option(200, "--n", help="Number of log-spaced frequencies."),
    exact: bool = typer.Option(
        False, "--exact", help="Compute boundaries directly instead of from the library."
    ),
    record: Optional[Path] = typer.Option(
        None,
        "--record",
        help="Draw this record's largest sine pulse on the plot, at each --record-scale.",
    ),
    record_scale: list[float] = typer.Option(
        [0.5, 1.0, 2.0], "--record-scale", help="Scale factors of the record's pulse [-]."
    ),
    units: Optional[str] = _UNITS_OPT,
    record_format: Optional[str] = _FORMAT_OPT,
    dt: Optional[float] = _DT_OPT,
    as_json: bool = typer.Option(False, "--json", help="Also print the JSON document."),
) -> None:
    """Minimum overturning sine-pulse amplitude of every mechanism, and the critical bands."""
    from .analysis import frequency_grid, record_pulse_doc, write_envelope

    f_p = frequency_grid(f_min, f_max, n)
    cf = _read_constants(constants)
    pulse = None
    if record is not None:
        motion = _read_record(record, record_format, units, dt)
        pulse = record_pulse_doc(cf, motion, _scales(record_scale, ctx.args), exact=exact)
    elif ctx.args:
        _fail(f"unexpected argument {ctx.args[0]!r}")
    doc = write_envelope(
        cf,
        f_p,
        out,
        exact=exact,
        title=f"Overturning envelopes: {constants.name}",
        record_pulse=pulse,
    )
    if as_json:
        _print_json(doc)
        return
    typer.echo(f"wrote {out / 'envelope.json'}, envelope.csv, envelope.png")
    typer.echo("critical mechanism by pulse frequency:")
    for band in doc["critical"]:
        typer.echo(f"  {band['f_min']:8.3f} - {band['f_max']:8.3f} Hz: {band['mechanism']}")
    if pulse is not None:
        p = pulse["pulse"]
        typer.echo(
            f"largest pulse of {pulse['record']}: {abs(p['a_p_g']):.4f} g at "
            f"{p['f_p_hz']:.3f} Hz (t = {p['t_start_s']:.2f} s)"
        )
        for point in pulse["points"]:
            names = ", ".join(point["overturns"]) or "none"
            typer.echo(f"  x{point['scale']:g}: {point['a_p_g']:.4f} g overturns {names}")


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


@app.command(context_settings={"allow_extra_args": True, "ignore_unknown_options": True})
@_user_errors
def report(
    ctx: typer.Context,
    constants: Path = typer.Argument(..., help="Kinematic-constants JSON file."),
    out: Path = typer.Option(..., "-o", "--out", help="HTML file to write."),
    record: Optional[Path] = typer.Option(
        None, "--record", help="Record for time histories and its spectrum (any format)."
    ),
    scale: list[float] = typer.Option([1.0], "--scale", help="Scale factors on the record."),
    units: Optional[str] = _UNITS_OPT,
    record_format: Optional[str] = _FORMAT_OPT,
    dt: Optional[float] = _DT_OPT,
    sf: str = _SF_OPT,
    building_height: Optional[float] = _BUILDING_HEIGHT_OPT,
    soil_factor: float = _SOIL_FACTOR_OPT,
    element_period: float = _ELEMENT_PERIOD_OPT,
    at_height: Optional[float] = typer.Option(
        None, "--at-height", help="Also tabulate the peak displacement [m] this far [m] up."
    ),
    criterion: Optional[str] = typer.Option(
        None, "--criterion", help="Verdict of the time histories: ratio (default) or exact."
    ),
    f_min: float = typer.Option(0.1, "--f-min", help="Lowest pulse frequency [Hz]."),
    f_max: float = typer.Option(10.0, "--f-max", help="Highest pulse frequency [Hz]."),
    n: int = typer.Option(200, "--n", help="Number of log-spaced frequencies."),
    exact: bool = typer.Option(False, "--exact", help="Exact envelopes, not the library."),
    title: Optional[str] = typer.Option(None, "--title", help="Title of the report."),
) -> None:
    """One self-contained HTML report: constants, envelopes, and with --record its histories."""
    from .analysis import Building, frequency_grid
    from .report.html import build_report, input_source, write_report

    scales = _scales(scale, ctx.args)
    f_p = frequency_grid(f_min, f_max, n)
    cf = _read_constants(constants)
    sources = [input_source("constants", constants.name, constants.read_bytes())]
    motion = None
    if record is not None:
        motion = _read_record(record, record_format, units, dt)
        sources.append(input_source("record", record.name, record.read_bytes()))
    options = {"scales": scales, "sf": sf, "building_height": building_height}
    options.update(soil_factor=soil_factor, element_period=element_period, at_height=at_height)
    options.update(criterion=criterion)
    options.update(f_min=f_min, f_max=f_max, n=n, exact=exact)
    text = build_report(
        cf,
        f_p,
        motion=motion,
        scales=scales,
        history={
            "sf": sf,
            "building": Building(building_height, soil_factor, element_period),
            "criterion": criterion,
            "at_height": at_height,
        },
        exact=exact,
        title=title or f"rockmech report: {constants.name}",
        sources=sources,
        request=options,
    )
    typer.echo(f"wrote {write_report(out, text)}")


@app.command()
@_user_errors
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
    from .api.server import run, settings_with

    run(settings_with(host=host, port=port, compute_workers=workers, compute_timeout_s=timeout))


def main() -> None:  # pragma: no cover - console entry point
    """Entry point of the ``rockmech`` console script."""
    app()
