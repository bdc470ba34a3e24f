"""The bundled demonstration: rectangular walls on the El Centro 1940 record.

``run_demo`` writes, to one folder:

* ``constants.json``: analytic kinematic constants of three rectangular walls;
* ``history.json``: peak ``|phi|/phi_ov`` and overturning of each wall at several scale
  factors of El Centro 1940 N-S, from the exact integrator;
* ``history.png``: the time histories ``phi/phi_ov``, one panel per scale factor, and
  ``history_record.png``: the record with its largest sine pulse and its spectrum;
* ``church_envelope.json``, ``.csv`` and ``.png``: minimum overturning pulse amplitudes
  of the example church's mechanisms (``examples/constants/church.json``), at ground
  level, with the critical mechanism per pulse frequency;
* ``church_history.json`` and ``.png``: El Centro 1940 against the church's mechanisms,
  each scaled up the structure by Eq. 28 (from the record's 5 % spectrum at its natural
  period);
* ``facade_constants.json`` and ``facade_envelope.{json,csv,png}``: the CAD path end to
  end, from the example façade scene (``examples/scenes/facade.3dm``, with floors, roof,
  vault, tie-bars and a crack) and its spec to kinematic constants and envelopes.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from importlib import resources
from pathlib import Path
from typing import Any, Optional

from shared_schema.constants import ConstantsFile
from shared_schema.errors import InputError
from shared_schema.extras import MissingExtra
from shared_schema.io import read_constants, write_constants
from shared_schema.paths import PathLike, as_path

from .core.model import G
from .core.records import GroundMotion
from .workflows.documents import frequency_grid
from .workflows.inputs import constants_from_scene_files
from .workflows.outputs import write_envelope, write_history
from .workflows.rundir import run_folder

__all__ = [
    "DEMO_WALLS",
    "EXAMPLES_DIR",
    "copy_examples",
    "examples_dir",
    "rectangular_block",
    "run_demo",
]


def examples_dir() -> Path:
    """Return the folder of the bundled examples (scenes, specs, constants, El Centro 1940).

    An installed wheel holds them as package data (``solver_service/data/examples``, which
    pyproject.toml maps from the repository's ``examples/``); a source tree has the
    repository's ``examples/`` folder.

    Raises
    ------
    InputError
        If neither exists (a broken installation).
    """
    bundled = resources.files(__package__ or "solver_service") / "data" / "examples"
    if isinstance(bundled, Path) and bundled.is_dir():
        return bundled
    source_tree = Path(__file__).resolve().parents[1] / "examples"
    if source_tree.is_dir():
        return source_tree
    raise InputError(
        f"the bundled examples are missing (looked in {bundled} and {source_tree}); "
        "reinstall rockmech",
        "examples",
    )


#: Files of the examples folder that are not examples (a clone's scene-building script).
_NOT_EXAMPLES = ("*.py", "*.pyc")


def copy_examples(
    out: PathLike = Path("examples"), on_note: Optional[Callable[[str], None]] = None
) -> list[Path]:
    """Copy the bundled examples into ``out``, so that the README's commands run from a wheel.

    ``out`` gets the layout of the repository's ``examples/`` (``constants/``, ``records/``,
    ``scenes/``, ``sites/``, ``specs/``). The copy is a rockmech run like any other
    (``workflows.rundir.run_folder``): it replaces only the files an earlier copy wrote and
    that are unchanged since; a file of the user's in the way stops it with one line naming
    the file, and nothing else in ``out`` is touched.

    Parameters
    ----------
    out : str or os.PathLike
        The folder to copy into (created if missing).
    on_note : callable, optional
        Called with each note of the output folder (``run_folder``).

    Returns
    -------
    list of Path
        The files written, under ``out``.
    """
    dest = as_path(out, "out")
    source = examples_dir()
    files = sorted(
        p
        for p in source.rglob("*")
        if p.is_file()
        and "__pycache__" not in p.parts
        and not any(p.match(pattern) for pattern in _NOT_EXAMPLES)
    )
    with run_folder(dest, on_note=on_note, command="examples") as stage:
        for path in files:
            target = stage / path.relative_to(source)
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(path.read_bytes())
    return [dest / path.relative_to(source) for path in files]


#: The bundled examples folder (see ``examples_dir``).
EXAMPLES_DIR = examples_dir()
#: Demo walls: id, description, thickness b [m], height h [m], rocking kind.
DEMO_WALLS = (
    ("W1", "free-standing brick wall 0.25 m x 3.0 m", 0.25, 3.0, "two_sided"),
    ("W2", "free-standing stone wall 0.50 m x 3.0 m", 0.50, 3.0, "two_sided"),
    (
        "F1",
        "stone facade 0.60 m x 6.0 m, restrained inward by transverse walls",
        0.60,
        6.0,
        "one_sided",
    ),
)
#: Scale factors applied to the record in the demo.
DEMO_SCALES = (0.5, 1.0, 1.5, 2.0, 3.0)


def rectangular_block(
    b: float, h: float, *, density: float = 1800.0, length: float = 1.0, one_sided: bool = False
) -> dict[str, Any]:
    """Kinematic constants of a rectangular block rocking about a base edge (theory §2.1).

    Parameters
    ----------
    b, h : float
        Thickness (in the rocking plane) and height [m].
    density : float
        Density [kg/m³].
    length : float
        Length out of plane [m].
    one_sided : bool
        Use the one-sided restitution of Eq. 26 instead of Housner's Eq. 25.

    Returns
    -------
    dict
        A mechanism in the kinematic-constants format: ``positive`` holds ``I0`` [kg m²],
        ``K`` [N m/rad], ``Q`` [kg m] and ``phi_cr`` [rad]; ``eta`` and its source.

    Notes
    -----
    ``M = rho b h l``, ``R = sqrt(b² + h²)/2``, ``alpha = atan(b/h)``,
    ``I_O = 4/3 M R²``, ``K = M g R``, ``Q = M R``, ``phi_cr = alpha`` (Eqs. 7–10), and
    ``eta = 1 - 1.5 sin²alpha`` (Eq. 25) or ``1 - 1.5 cos²alpha`` (Eq. 26).

    Examples
    --------
    >>> c = rectangular_block(0.5, 3.0)
    >>> round(c["positive"]["phi_cr"], 6)
    0.165149
    """
    mass = density * b * h * length
    r = 0.5 * math.hypot(b, h)
    alpha = math.atan2(b, h)
    i_o = 4.0 / 3.0 * mass * r * r
    ratio = mass * r * r / i_o
    if one_sided:
        eta, source = 1.0 - 2.0 * ratio * math.cos(alpha) ** 2, "one_sided_eq26"
    else:
        eta, source = 1.0 - 2.0 * ratio * math.sin(alpha) ** 2, "housner_rectangular"
    return {
        "typology": "single_block",
        "rocking": "one_sided" if one_sided else "two_sided",
        "positive": {"I0": i_o, "K": mass * G * r, "Q": mass * r, "phi_cr": alpha, "M_F": 0.0},
        "eta": eta,
        "eta_source": source,
        "geometry": {
            "b_m": b,
            "h_m": h,
            "length_m": length,
            "density_kg_m3": density,
            "mass_kg": mass,
            "R_m": r,
            "alpha_rad": alpha,
        },
    }


def demo_constants() -> ConstantsFile:
    """Return the demo walls as a validated kinematic-constants file."""
    mechanisms = []
    for ident, name, b, h, rocking in DEMO_WALLS:
        mech = rectangular_block(b, h, one_sided=rocking == "one_sided")
        mech.update(id=ident, name=name, provenance={"source": "rockmech demo (analytic)"})
        mechanisms.append(mech)
    return ConstantsFile.model_validate({"mechanisms": mechanisms})


def run_demo(
    out_dir: Path,
    record_path: Path | None = None,
    *,
    on_skip: Optional[Callable[[str], None]] = None,
) -> dict[str, Path]:
    """Run the demonstration and write its files to ``out_dir``.

    Parameters
    ----------
    out_dir : Path
        Output folder (created if missing).
    record_path : Path, optional
        Two-column record in g; defaults to the bundled El Centro 1940 N-S.
    on_skip : callable, optional
        Called with a one-line note when the CAD part is skipped because the ``geometry``
        extra is missing. Without it, ``MissingExtra`` is raised instead.

    Returns
    -------
    dict
        Paths of the written files by kind.
    """
    out_dir.mkdir(parents=True, exist_ok=True)
    record_path = record_path or EXAMPLES_DIR / "records" / "elcentro_NS.dat"
    record = GroundMotion.from_two_column(record_path, units="g")
    cf = demo_constants()
    constants_path = out_dir / "constants.json"
    write_constants(cf, constants_path)
    write_history(
        cf,
        record,
        list(DEMO_SCALES),
        out_dir,
        title=f"{record.name}: rocking of the demo walls (exact integrator)",
    )
    env_paths = church_envelope(out_dir)
    env_paths["church_history"] = church_history(out_dir, record)
    try:
        cad_paths = facade_from_scene(out_dir)
    except MissingExtra as exc:
        if on_skip is None:
            raise
        on_skip(f"skipped the CAD example (facade.3dm -> constants -> envelopes): {exc}")
        cad_paths = {}
    return {
        "constants": constants_path,
        "history": out_dir / "history.json",
        "plot": out_dir / "history.png",
        "record_plot": out_dir / "history_record.png",
        **env_paths,
        **cad_paths,
    }


def facade_from_scene(out_dir: Path) -> dict[str, Path]:
    """Scene -> constants -> envelopes for the example façade (the CAD path end to end)."""
    scene_path = EXAMPLES_DIR / "scenes" / "facade.3dm"
    spec_path = EXAMPLES_DIR / "specs" / "facade.spec.json"
    cf = constants_from_scene_files(scene_path, spec_path)
    constants_path = out_dir / "facade_constants.json"
    write_constants(cf, constants_path)
    write_envelope(
        cf,
        frequency_grid(0.1, 10.0, 200),
        out_dir,
        stem="facade_envelope",
        title="Example façade (from facade.3dm): overturning envelopes",
    )
    return {
        "facade_constants": constants_path,
        "facade_envelope": out_dir / "facade_envelope.json",
        "facade_envelope_plot": out_dir / "facade_envelope.png",
    }


def church_history(out_dir: Path, record: GroundMotion) -> Path:
    """El Centro against the example church's mechanisms, scaled up the structure by Eq. 28.

    A time history needs a coefficient of restitution: the one-sided façade without eta (an
    envelope-only example) is listed under ``skipped`` in the document, with the reason.
    """
    cf = read_constants(EXAMPLES_DIR / "constants" / "church.json")
    write_history(
        cf,
        record,
        list(DEMO_SCALES),
        out_dir,
        stem="church_history",
        title=f"{record.name} on the example church, scaled up the structure by Eq. 28",
        sf="eq28",
    )
    return out_dir / "church_history.json"


def church_envelope(out_dir: Path) -> dict[str, Path]:
    """Write the example church's envelopes and critical bands (JSON, CSV, PNG)."""
    cf = read_constants(EXAMPLES_DIR / "constants" / "church.json")
    stem = "church_envelope"
    write_envelope(
        cf,
        frequency_grid(0.1, 10.0, 200),
        out_dir,
        stem=stem,
        title="Example church: overturning envelopes and the critical mechanism",
    )
    return {
        kind: out_dir / f"{stem}.{ext}"
        for kind, ext in (("envelope", "json"), ("envelope_csv", "csv"), ("envelope_plot", "png"))
    }
