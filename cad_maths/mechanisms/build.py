"""Spec + scene -> kinematic-constants file, through the registry of typologies.

The result validates against ``shared_schema.constants`` and carries, per mechanism, a
geometry summary (mass, centre of mass, R, alpha, I_O per side; for loaded walls the
combined quantities and every element) and its provenance (source files, object ids,
options, warnings from mesh repair).
"""

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence, Tuple, Type

import numpy as np
from pydantic import ValidationError

from cad_maths.mechanisms import loaded, multi_block_cad, single, two_block_cad
from cad_maths.mechanisms.base import Builder, MechanismSides
from cad_maths.mechanisms.single import AXIS_TILT_TOL, resolve_axis
from cad_maths.mechanisms.thrust import ThrustTable
from shared_schema.constants import ConstantsFile, input_error_from_validation
from shared_schema.errors import GeometryError, InputError, RockmechError
from shared_schema.extras import MissingExtra
from shared_schema.rules import eta_range
from shared_schema.spec import (
    LoadedWallSpec,
    MechanismBase,
    MultiBlockSpec,
    SingleBlockSpec,
    TwoBlockSpec,
    typology_of,
)

__all__ = [
    "MECHANISMS",
    "MechanismFailure",
    "TypologyEntry",
    "constants_and_failures",
    "constants_from_spec",
    "failures_error",
    "mechanism_entry",
]

#: Two sides whose constants agree to this relative tolerance are stored once (symmetric).
SYMMETRY_RTOL = 1e-9


def _same(a: Dict[str, float], b: Dict[str, float]) -> bool:
    return all(abs(a[k] - b[k]) <= SYMMETRY_RTOL * max(abs(a[k]), abs(b[k]), 1e-300) for k in a)


def _mirror_image(positive: Dict[str, float], negative: Dict[str, float]) -> bool:
    """Tell whether the negative side is the positive side's mirror image.

    The magnitudes agree and ``M_F``, signed in the positive sense on both sides
    (``shared_schema.constants``), changes sign; the solver's constants then coincide.
    """
    mirrored = dict(negative, M_F=-negative.get("M_F", 0.0))
    return all(
        abs(positive[k] - mirrored[k])
        <= SYMMETRY_RTOL * max(abs(positive[k]), abs(mirrored[k]), 1e-300)
        for k in positive
    )


#: Relative error on lam (and p_eq²) accepted from the horizontal-axis formulas when an
#: inclined axis is allowed (``allow_non_horizontal_axis``).
TILT_RTOL = 1e-3
#: Largest tilt of a rocking axis for any body [rad]: ``(pi/2) sqrt(2 TILT_RTOL)``, the bound
#: below at the largest possible alpha.
MAX_AXIS_TILT = 0.5 * math.pi * math.sqrt(2.0 * TILT_RTOL)


@dataclass(frozen=True)
class TypologyEntry:
    """One typology of the registry: its spec model and its builder.

    Attributes
    ----------
    spec : type
        Its spec model (``shared_schema.spec.TYPOLOGY_SPECS``); its ``typology`` literal is
        the typology's name.
    build : Builder
        ``(spec, scene, thrust_table) -> MechanismSides``.
    largest_tilt : float
        Largest tilt of its rocking axis from the horizontal the builder bears when the spec
        allows an inclined axis [rad].
    """

    spec: Type[MechanismBase]
    build: Builder
    largest_tilt: float = MAX_AXIS_TILT

    @property
    def typology(self) -> str:
        """The typology's name (the spec model's ``typology`` literal)."""
        return typology_of(self.spec)


#: Mechanism typologies and their builders, one line each, keyed by the spec model's
#: ``typology``. Adding a typology: its spec model in ``shared_schema.spec``
#: (``TYPOLOGY_SPECS``), a module with its builder returning ``MechanismSides``, one line
#: here, then its Rhino flow and command (CONTRIBUTING.md).
MECHANISMS: Dict[str, TypologyEntry] = {
    entry.typology: entry
    for entry in (
        TypologyEntry(SingleBlockSpec, single.build_single_block),
        TypologyEntry(LoadedWallSpec, loaded.build_loaded_wall),
        TypologyEntry(TwoBlockSpec, two_block_cad.build_two_block, largest_tilt=AXIS_TILT_TOL),
        TypologyEntry(MultiBlockSpec, multi_block_cad.build_multi_block),
    )
}


def _axis_tilt(spec: Any, scene: Any, largest: float) -> float:
    """Largest tilt from the horizontal of the spec's rocking axes [rad] (0 without axes).

    Raises
    ------
    GeometryError
        An inclined axis is allowed but tilted beyond ``largest``, the typology's
        ``TypologyEntry.largest_tilt`` (refused up front, before any solid is cut).
    """
    tilts = [0.0]
    for key in ("axis", "axis_negative"):
        axis = getattr(spec, key, None)
        if axis is None:
            continue
        start, end = resolve_axis(scene, axis, f"{spec.id}.{key}")
        u = (end - start) / float(np.linalg.norm(end - start))
        tilts.append(math.asin(min(abs(float(u[2])), 1.0)))
    tilt = max(tilts)
    if tilt <= AXIS_TILT_TOL or not getattr(spec, "allow_non_horizontal_axis", False):
        return tilt  # the builder refuses a tilt beyond AXIS_TILT_TOL without the flag
    if tilt > largest:
        raise GeometryError(
            f"{spec.id}.axis: the axis is inclined by {math.degrees(tilt):.3f} deg; the "
            f"largest tilt supported for a {spec.typology} is {math.degrees(largest):.3f} deg. "
            "The constants (theory Eqs. 7-16, 18-23) are derived for a horizontal axis; about "
            "an axis inclined by t, lam is overestimated by about t²/(2 alpha²). Model the "
            "mechanism with a horizontal axis"
        )
    return tilt


def _check_tilt(spec: Any, tilt: float, geometry: Dict[str, Any]) -> str:
    """Refuse a tilt that the horizontal-axis formulas do not bear; else a warning.

    About an axis inclined by ``t`` the potential energy is ``M g R cos(t) cos(phi - alpha)``
    with ``alpha`` the angle, in the plane normal to the axis, between the axis-to-G
    perpendicular and the vertical's projection: exactly ``K = M g R cos(t)``,
    ``phi_cr = alpha``, ``Q = M R``. The horizontal-axis formulas use ``K = M g R`` and an
    angle ``alpha_used`` with ``cos(alpha_used) = cos(alpha) cos(t)``, so they overestimate
    lam by ``1 - alpha cos(t)/alpha_used``, about ``t²/(2 alpha²)`` (relative).
    """
    alphas = [
        float(geometry[side]["alpha_rad"])
        for side in ("positive", "negative")
        if isinstance(geometry.get(side), dict) and "alpha_rad" in geometry[side]
    ]
    alpha = min(alphas) if alphas else 0.5 * math.pi
    # The angle about the inclined axis: cos(alpha_true) = cos(alpha_used) / cos(t).
    true_alpha = math.acos(min(math.cos(alpha) / math.cos(tilt), 1.0))
    error = 1.0 - true_alpha * math.cos(tilt) / alpha
    largest = true_alpha * math.sqrt(2.0 * TILT_RTOL)
    if error > TILT_RTOL:
        raise GeometryError(
            f"{spec.id}.axis: the axis is inclined by {math.degrees(tilt):.3f} deg, which "
            f"overestimates lam by {100 * error:.2g} % (the constants take the axis "
            f"horizontal); the largest tilt supported for this body (alpha = "
            f"{true_alpha:.4f} rad) is {math.degrees(largest):.3f} deg"
        )
    return (
        f"{spec.id}.axis: the axis is inclined by {math.degrees(tilt):.3f} deg; the constants "
        f"take it horizontal, which overestimates lam by {100 * error:.2g} % at most here"
    )


def mechanism_entry(spec: Any, scene: Any, table: Any) -> Dict[str, Any]:
    """One mechanism of the constants file from its spec (through ``MECHANISMS``)."""
    typology = MECHANISMS.get(spec.typology)
    if typology is None:
        raise InputError(
            f"no builder for typology {spec.typology!r}; known: {sorted(MECHANISMS)}",
            f"{spec.id}.typology",
        )
    tilt = _axis_tilt(spec, scene, typology.largest_tilt)
    sides = typology.build(spec, scene, table)
    if tilt > AXIS_TILT_TOL:
        sides.warnings.append(_check_tilt(spec, tilt, sides.geometry))
    # issue #14: admissible but implausible inputs are said, not silently used
    sides.warnings.extend(spec.plausibility_notes())
    size_note = scene.size_note(sides.object_ids, spec.id)
    if size_note is not None:
        sides.warnings.append(size_note)
    entry: Dict[str, Any] = {
        "id": spec.id,
        "name": spec.name or spec.id,
        "typology": spec.typology,
        "rocking": spec.rocking,
    }
    return _finish(spec, entry, sides)


def _directional_etas(spec: Any, eta_info: Dict[str, Any]) -> Dict[str, float]:
    """``eta_to_negative``/``eta_to_positive`` of a two-sided mechanism whose impacts differ.

    The builders record the computed restitution of both impact directions in ``eta_info``
    (``eta_pos_to_neg``, ``eta_neg_to_pos``); they are written only when they differ, and
    clamped to [0, 1] like ``eta``.
    """
    to_neg, to_pos = eta_info.get("eta_pos_to_neg"), eta_info.get("eta_neg_to_pos")
    if spec.rocking != "two_sided" or to_neg is None or to_pos is None:
        return {}
    if abs(to_neg - to_pos) <= SYMMETRY_RTOL * max(abs(to_neg), abs(to_pos), 1e-300):
        return {}
    return {
        "eta_to_negative": min(max(float(to_neg), 0.0), 1.0),
        "eta_to_positive": min(max(float(to_pos), 0.0), 1.0),
    }


def _finish(spec: Any, entry: Dict[str, Any], sides: MechanismSides) -> Dict[str, Any]:
    """Complete an entry: sides, restitution, amplification, geometry and provenance.

    The negative side is stored only where it is not the positive side's mirror image. A computed
    ``eta`` outside the range of the rocking kind ([0, 1] two-sided, [-1, 0] one-sided; a
    very stocky body) is clamped with a warning; a user ``eta`` overrides it, and the
    computed value is kept in the geometry summary.
    """
    positive, negative, eta = sides.positive, sides.negative, sides.eta
    geometry, eta_info, warnings = sides.geometry, sides.eta_info, sides.warnings
    vw_pos = sides.virtual_work.get("positive")
    vw_neg = sides.virtual_work.get("negative")
    entry["positive"] = dict(positive) if vw_pos is None else {**positive, "virtual_work": vw_pos}
    symmetric = negative is not None and _mirror_image(positive, negative)
    if symmetric and (vw_pos is None) != (vw_neg is None):
        symmetric = False
    if symmetric and vw_pos is not None and vw_neg is not None:
        symmetric = _same(vw_pos, vw_neg)
    if negative is not None and not symmetric:
        entry["negative"] = (
            dict(negative) if vw_neg is None else {**negative, "virtual_work": vw_neg}
        )
    if eta is not None:
        lo, hi = eta_range(spec.rocking == "one_sided")
        if not lo <= eta <= hi:
            clamped = min(max(eta, lo), hi)
            warnings.append(
                f"{spec.id}: {sides.eta_source} gives eta = {eta:.4f}, outside [{lo:g}, {hi:g}] "
                f"for {spec.rocking} rocking (a very stocky body); eta set to {clamped:g}"
            )
            eta = clamped
    if spec.eta is not None:
        entry["eta"], entry["eta_source"] = spec.eta, "user"
        if eta is not None:
            eta_info["computed"] = eta
    elif eta is not None:
        entry["eta"], entry["eta_source"] = eta, sides.eta_source
        entry.update(_directional_etas(spec, eta_info))
    if eta_info:
        geometry["restitution"] = eta_info
    if spec.amplification is not None:
        entry["amplification"] = spec.amplification.model_dump()
    entry["geometry"] = geometry
    entry["provenance"] = {"object_ids": sides.object_ids, "warnings": warnings}
    return entry


@dataclass(frozen=True)
class MechanismFailure:
    """Why one mechanism of a spec could not be computed.

    Attributes
    ----------
    id : str
        The mechanism's id.
    error : RockmechError
        The error (its message names the field or object, and the mechanism).
    """

    id: str
    error: RockmechError

    @property
    def message(self) -> str:
        """The error's message, prefixed with the mechanism's id unless it already names it."""
        text = str(self.error)
        return text if text.startswith(self.id) else f"{self.id}: {text}"


def failures_error(failures: Sequence[MechanismFailure], total: int) -> RockmechError:
    """One error listing every failed mechanism, of the first failure's class.

    Parameters
    ----------
    failures : sequence of MechanismFailure
        At least one.
    total : int
        Number of mechanisms in the spec.
    """
    first = failures[0].error
    if total == 1 and len(failures) == 1:
        return first
    lines = [f"{len(failures)} of {total} mechanisms failed:"]
    lines += [f"  {f.message}" for f in failures]
    out = type(first)("\n".join(lines))
    if isinstance(first, InputError) and isinstance(out, InputError):
        out.field = first.field  # the first failure's field, for the REST answer
    return out


#: Metres per unit of the points written in a spec (``SpecFile.units``; "file" is the scene's).
POINT_UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001}


def _point_scale(spec_file: Any, scene: Any) -> float:
    units = spec_file.units or "m"
    return float(scene.unit_scale) if units == "file" else POINT_UNITS[units]


def _scaled(p: Any, scale: float) -> Any:
    return [float(v) * scale for v in p] if isinstance(p, list) else p


def _points_in_metres(spec: Any, scale: float) -> Any:
    """Return the mechanism spec with its written points (axes, cracks, hinges) in metres.

    Each typology has only some of these fields (``shared_schema.spec.TYPOLOGY_SPECS``).
    """
    if scale == 1.0:
        return spec
    update: Dict[str, Any] = {}
    for key in ("axis", "axis_negative"):
        axis = getattr(spec, key, None)
        if axis is not None and axis.start is not None:
            update[key] = axis.model_copy(
                update={"start": _scaled(axis.start, scale), "end": _scaled(axis.end, scale)}
            )
    cracks = getattr(spec, "cracks", [])
    if any(c.points is not None or c.keep_point is not None for c in cracks):
        update["cracks"] = [
            c.model_copy(
                update={
                    "points": None if c.points is None else [_scaled(p, scale) for p in c.points],
                    "keep_point": None if c.keep_point is None else _scaled(c.keep_point, scale),
                }
            )
            for c in cracks
        ]
    for key in ("hinges", "hinges_negative"):
        hinges = getattr(spec, key, None)
        if hinges is not None:
            update[key] = hinges.model_copy(
                update={n: _scaled(getattr(hinges, n), scale) for n in ("A", "B", "C", "D")}
            )
    if getattr(spec, "hinge_height", None) is not None:
        update["hinge_height"] = float(spec.hinge_height) * scale
    return spec.model_copy(update=update)


def _written_points(spec: Any) -> bool:
    axes = [getattr(spec, k, None) for k in ("axis", "axis_negative")]
    axes = [a for a in axes if a is not None and a.start is not None]
    hinges = [getattr(spec, k, None) for k in ("hinges", "hinges_negative")]
    hinges = [h for h in hinges if h is not None]
    return bool(
        axes
        or any(
            c.points is not None or c.keep_point is not None for c in getattr(spec, "cracks", [])
        )
        or any(isinstance(getattr(h, n), list) for h in hinges for n in ("A", "B", "C", "D"))
    )


def _units_hint(spec_file: Any, scene: Any) -> str:
    units = spec_file.units or "m"
    said = "the spec's 'units'" if spec_file.units is not None else "the default"
    return (
        f" (the points written in the spec are read in {units} [{said}] and the scene is in "
        f'{scene.units}: if they are in another unit, set the spec\'s "units" to "file", '
        '"m", "cm" or "mm")'
    )


def _body_size_note(spec: Any, scene: Any) -> Optional[str]:
    """Return the size warning of a mechanism's body (``scene.size_note``) without its id.

    Where the axis, a crack or a hinge misses a body of kilometres or millimetres, the
    scene's length unit is the likely cause, so the error says it (#25).
    """
    ids = []
    for _, group in spec.body_groups():
        for sel in group.objects:
            try:
                ids += [obj.id for obj in scene.find(sel)]
            except RockmechError:
                continue  # a selector error is reported by the builder
    try:
        note = scene.size_note(ids, spec.id) if ids else None
    except RockmechError:
        return None  # the body's own defect is the builder's error to report
    return note.split(": ", 1)[1] if note else None


#: Words of the geometry errors that an axis, crack or hinge far from the body gives.
FAR_FROM_BODY = (
    "does not touch the body",
    "misses the body",
    "not at the body's base",
    "other side of the centre of mass",
)


def constants_and_failures(
    spec_file: Any,
    scene: Any,
    *,
    scene_name: str,
    spec_name: str,
    spec_dir: Optional[Path] = None,
) -> Tuple[Optional[ConstantsFile], List[MechanismFailure]]:
    """Compute every mechanism of a spec; collect the failures instead of stopping at one.

    Returns
    -------
    constants : ConstantsFile or None
        The mechanisms that succeeded, in spec order; None when none did.
    failures : list of MechanismFailure
        The mechanisms that failed, in spec order, each with its error.
    """
    table_path = None
    if spec_file.thrust_table is not None:
        table_path = Path(spec_file.thrust_table)
        if not table_path.is_absolute() and spec_dir is not None:
            table_path = spec_dir / table_path
    table = ThrustTable.load(table_path)
    mechanisms: List[Dict[str, Any]] = []
    failures: List[MechanismFailure] = []
    scale = _point_scale(spec_file, scene)
    for given in spec_file.mechanisms:
        spec = _points_in_metres(given, scale)
        entry: Dict[str, Any] = {}
        try:
            entry = mechanism_entry(spec, scene, table)
            entry["provenance"].update(
                {
                    "scene": scene_name,
                    "spec": spec_name,
                    "scene_units": scene.units,
                    "thrust_table": table.name if getattr(spec, "vaults", None) else None,
                }
            )
            if entry["provenance"]["thrust_table"] is None:
                del entry["provenance"]["thrust_table"]
            if spec_file.units is not None:
                entry["provenance"]["spec_point_units"] = spec_file.units
            # Validate each entry on its own, so that one bad entry does not hide the others.
            ConstantsFile.model_validate({"mechanisms": [entry]})
        except ValidationError as exc:
            err = input_error_from_validation(exc, {"mechanisms": [entry]})
            field = (err.field or "").replace(f"mechanisms[0] (id {spec.id!r})", spec.id)
            failures.append(MechanismFailure(spec.id, InputError(err.reason, field or spec.id)))
            continue
        except GeometryError as exc:
            # A body far from the written points most often means points in another unit:
            # the scene's (a body of kilometres: a mm scan read as m), else the spec's.
            far = any(words in str(exc) for words in FAR_FROM_BODY)
            size = _body_size_note(spec, scene) if far else None
            if size is not None:
                exc = GeometryError(f"{exc} ({size})")
            elif far and _written_points(given):
                exc = GeometryError(str(exc) + _units_hint(spec_file, scene))
            failures.append(MechanismFailure(spec.id, exc))
            continue
        except MissingExtra:
            raise  # the installation, not this mechanism: every mechanism would fail alike
        except RockmechError as exc:
            failures.append(MechanismFailure(spec.id, exc))
            continue
        mechanisms.append(entry)
    if not mechanisms:
        return None, failures
    return ConstantsFile.model_validate({"mechanisms": mechanisms}), failures


def constants_from_spec(
    spec_file: Any,
    scene: Any,
    *,
    scene_name: str,
    spec_name: str,
    spec_dir: Optional[Path] = None,
) -> ConstantsFile:
    """Kinematic-constants file for every mechanism of a spec file.

    Raises
    ------
    RockmechError
        If any mechanism fails: one error listing every failed mechanism (the class of the
        first failure), so that a user sees all of them at once.
    """
    cf, failures = constants_and_failures(
        spec_file, scene, scene_name=scene_name, spec_name=spec_name, spec_dir=spec_dir
    )
    if failures:
        raise failures_error(failures, len(spec_file.mechanisms))
    assert cf is not None
    return cf
