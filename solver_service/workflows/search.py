"""``rockmech search``: the mechanisms of a façade found, built and ranked by how they rock.

``search_run`` takes a scene and a search spec and returns a :class:`SearchRun`:

1. the maths (``cad_maths.search.engine.run_search``): the building read as prisms, the
   catalogue's candidates refined on the exact static multiplier λ0, the global upper-bound
   check per façade and direction, the sliding flags;
2. the ``candidates.keep`` candidates of least λ0 become mechanism specs of the existing
   typologies and go through the existing constants builder
   (``cad_maths.search.specs.build_candidates``); its exact λ0 and mass agree with the
   search's to 1e-9 on exact prisms, and its linearised λ is reported beside λ0;
3. every built mechanism is ranked by its overturning acceleration over the pulse frequency
   band (``documents.envelope_doc``: the library's envelopes, or the exact solver's): the
   score is the geometric mean of ``a_p,min`` over the band; the ``ranking.keep`` best run
   the records (exact solver, ``simulate_batch``: the smallest scale factor of each record
   that overturns them) and the code check (``assess.check_doc``: α0 and the verdict);
4. the document (``search.json``) says where the static (λ0) and the dynamic rankings differ.

``write_search_files`` writes the outputs into a staged folder (``write_search`` into a run
folder, through ``rundir.run_folder``): ``search.json``, ``search.spec.json`` (the spec the
existing commands and Rhino reopen), ``constants.json``, ``search.3dm`` (the search's scene
with a crack layer) and ``search.png`` (the top mechanisms on the façade).
"""

from __future__ import annotations

import json
import math
import tempfile
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Optional, Sequence, Union

import numpy as np

from cad_maths.mechanisms.build import MechanismFailure
from cad_maths.scene_base import BaseScene
from cad_maths.scenes import read_scene
from cad_maths.search.engine import (
    MISSED_GAP,
    SearchResult,
    rank_order,
    run_search,
    sliding_check,
)
from cad_maths.search.families import Candidate, ground_height
from cad_maths.search.prism import segment_intervals
from cad_maths.search.specs import AGREEMENT_RTOL, build_candidates
from shared_schema.atomic import write_atomic
from shared_schema.constants import ConstantsFile, json_document
from shared_schema.documents.envelope import EnvelopeDocument
from shared_schema.documents.search import SearchDocument
from shared_schema.errors import InputError, RockmechError, wrong_type
from shared_schema.extras import require
from shared_schema.io import stamped, write_constants
from shared_schema.paths import (
    PATH_TYPES,
    PathLike,
    Source,
    as_path,
    is_path,
    read_source,
    readable_folder,
)
from shared_schema.rules import check_file
from shared_schema.search import SearchSpec, parse_search_spec
from shared_schema.site import SiteFile
from shared_schema.spec import SpecFile
from shared_schema.text import decode_text
from shared_schema.version import __version__

from ..codes.floor_spectra import participation_first_mode
from .adapter import to_rocking_model
from .codecheck import T1_TOLERANCE, building_period
from .documents import envelope_doc, log_grid
from .rundir import run_folder
from .units import stamp

if TYPE_CHECKING:
    from ..core.envelope import OverturningLibrary

# Loaded by the steps that need them, not with the module (#37, #38): the exact solver
# (numba) for the records, the code check (workflows.assess) for a site, the record readers
# for records, matplotlib for the figure. A search without records or site loads none.

__all__ = [
    "SearchRun",
    "check_first_mode",
    "crack_patches",
    "first_mode",
    "read_search_spec",
    "scales_to_overturn",
    "search_3dm",
    "search_from_files",
    "search_run",
    "write_search",
    "write_search_files",
]

#: Work limit of one search [evaluations of λ0]: the command line lifts it with
#: ``--no-limits``, a REST request may lower it (about 0.2 ms each on one core).
MAX_EVALUATIONS = 200_000
#: Work limit of one global check [macro-blocks] (about 1 s for 300 on one core).
MAX_LP_BLOCKS = 2_000


@dataclass
class SearchRun:
    """A search, built and ranked.

    Attributes
    ----------
    doc : SearchDocument
        The document (``search.json`` is its ``to_dict()``): candidates, rankings, the
        global checks, records and code check, read as attributes (``doc.find(id).lam0``).
    spec_file : SpecFile or None
        The mechanism spec of the built candidates (``search.spec.json``).
    constants : ConstantsFile or None
        Their constants (``constants.json``).
    result : SearchResult
        The maths: the building, every candidate, the checks.
    ids : dict of int to str
        Mechanism id of each candidate (by its index in ``result.candidates``).
    """

    doc: SearchDocument
    spec_file: Optional[SpecFile]
    constants: Optional[ConstantsFile]
    result: SearchResult
    ids: dict[int, str] = field(default_factory=dict)

    def candidates_by_id(self) -> dict[str, Candidate]:
        """Return the search's candidate behind each mechanism id (``ids`` read the other way)."""
        return {mid: self.result.candidates[k] for k, mid in self.ids.items()}


#: What a search spec must be, for the messages on empty, binary or non-JSON files.
SEARCH_SPEC_EXPECTED = 'a search spec (JSON, {"walls": [...], "levels": [...], ...})'


def read_search_spec(path: Source) -> SearchSpec:
    """Read and validate a search spec file; errors name the spec and the field.

    An empty, binary (gzip, a workbook) or non-UTF-8 file is told as such, naming the file
    (``shared_schema.text.decode_text``; issue #36), as every other input file; a missing
    file or a folder names the path (field ``spec``).

    Parameters
    ----------
    path : str, os.PathLike or file object
        The search spec (JSON), as a path or an open file (``paths.read_source``). Its
        ``ranking.site`` and ``ranking.records`` are relative to its folder: give that folder
        to ``search`` as ``spec_dir``.
    """
    raw, name = read_source(path, "spec")
    text = decode_text(raw, name, "spec", SEARCH_SPEC_EXPECTED)
    try:
        json_document(text)  # malformed JSON: one line
    except InputError as exc:
        raise InputError(f"{name}: {exc.reason}; expected {SEARCH_SPEC_EXPECTED}", "spec") from None
    return parse_search_spec(text, name)


#: A site's building height this far (relative) from the scene's walls' gets a note.
HEIGHT_NOTE_RTOL = 0.1
#: Where Z is measured from, in the document.
Z_RULE = (
    "Z is the height of the base of a mechanism's moving part (its hinge line; a two-block "
    "wall's or a corner's base) above the ground, the lowest base of the scene's walls"
)
#: The stated assumption of a search without building data.
NO_BUILDING_DATA = (
    "no building data (no building in the site file, no first_mode in the search spec): "
    "every mechanism is ranked on the ground motion, as if it stood on the ground, "
    "including those above it; the code check of a mechanism above ground is incomplete; "
    "the constants written carry no height (amplification needs f_n and h_e), so "
    "`rockmech check` on them takes every mechanism at ground level"
)


def first_mode(spec: SearchSpec, site: Any, bld: Any) -> dict[str, Any]:
    """Return the building's first mode for the mechanisms above ground, and its source.

    From the search spec's ``first_mode`` (f_n, h_e); else from the site's ``building``:
    ``T1`` as the code check takes it (``codecheck.building_period``: ``building.T1``, else
    Circolare 2019 [C7.3.2]) and ``h_e = H / γ1 = H (2n + 1)/(3n)``, the effective height
    ``Σ m h² / Σ m h`` of the linear first mode of ``n`` equal storeys ([C7.2.10]'s γ1, so
    that Eq. 28's ``h/h_e`` is the floor spectrum's ``γ1 ψ(z)``, theory §7.2, §11.5).

    Returns
    -------
    dict
        ``given`` (whether there is building data), ``f_n_hz``, ``T1_s``, ``T1_source``,
        ``h_e_m``, ``h_e_source``, ``ground_z_m``, ``Z_rule`` and ``notes``; without data
        the frequencies are None and ``notes`` states the ground-level assumption.

    Raises
    ------
    InputError
        ``first_mode.f_n`` whose period differs from the site's ``building.T1`` by more
        than ``codecheck.T1_TOLERANCE`` (one period decides both the ranking and the check).
    """
    ground = ground_height(bld)
    top = max(w.z_hi for w in bld.walls.values()) - ground
    info: dict[str, Any] = {
        "given": False,
        "f_n_hz": None,
        "T1_s": None,
        "T1_source": None,
        "h_e_m": None,
        "h_e_source": None,
        "ground_z_m": ground,
        "Z_rule": Z_RULE,
        "notes": [],
    }
    b = None if site is None else site.building
    fm = spec.first_mode
    if fm is not None:
        check_first_mode(spec, site)
        info.update(
            given=True,
            f_n_hz=fm.f_n,
            T1_s=1.0 / fm.f_n,
            T1_source="search spec first_mode.f_n (T1 = 1/f_n)",
            h_e_m=fm.h_e,
            h_e_source="search spec first_mode.h_e",
        )
    elif b is not None:
        t1, t1_source = building_period(site)
        n = int(b.storeys)
        gamma = participation_first_mode(n)
        info.update(
            given=True,
            f_n_hz=1.0 / t1,
            T1_s=t1,
            T1_source=t1_source,
            h_e_m=b.height / gamma,
            h_e_source=(
                f"site building: h_e = H (2n + 1)/(3n) = {b.height:g} m x {1.0 / gamma:.6g} "
                f"(n = {n}), the effective height of the linear first mode of equal storeys "
                "(Circ. 2019 [C7.2.10]: gamma1 = 3n/(2n + 1), h_e = H/gamma1)"
            ),
        )
    else:
        info["notes"].append(NO_BUILDING_DATA)
        return info
    if b is not None and abs(b.height - top) > HEIGHT_NOTE_RTOL * b.height:
        info["notes"].append(
            f"the site's building.height = {b.height:g} m, the scene's walls reach {top:.4g} m "
            "above their lowest base: Z is measured from that base and the floor spectrum's "
            "psi = Z/H takes the site's H; check that both describe the same building"
        )
    return info


def check_first_mode(spec: SearchSpec, site: Any) -> None:
    """Refuse a search spec's ``first_mode.f_n`` that contradicts the site's ``building.T1``.

    Raises
    ------
    InputError
        On field ``first_mode.f_n``: the two periods differ by more than ``T1_TOLERANCE``.
    """
    fm = spec.first_mode
    b = None if site is None else site.building
    if fm is None or b is None or b.T1 is None:
        return
    t_fn = 1.0 / fm.f_n
    if abs(t_fn - b.T1) > T1_TOLERANCE * b.T1:
        raise InputError(
            f"first_mode.f_n = {fm.f_n:g} Hz (1/f_n = {t_fn:.4g} s) conflicts with the site's "
            f"building.T1 = {b.T1:g} s: one first period decides the ranking and the code "
            "check; remove one or make them agree",
            "first_mode.f_n",
        )


def _ids(n: int) -> list[str]:
    width = max(2, len(str(n)))
    return [f"S{k + 1:0{width}d}" for k in range(n)]


def scales_to_overturn(
    cf: ConstantsFile, motion: Any, grid: Optional[tuple[float, float, int]] = None
) -> list[dict[str, Any]]:
    """Find the smallest scale factor of a record that overturns each mechanism (exact solver).

    Parameters
    ----------
    cf : ConstantsFile
        The mechanisms (each needs ``eta``).
    motion : GroundMotion
        The record.
    grid : (float, float, int), optional
        Scale factors tried: log-spaced from the first to the second, that many (default
        ``scaling.SCALE_GRID``).

    Returns
    -------
    list of dict
        Per mechanism: ``scale`` (None when none up to the grid's top overturns), the
        bracket ``[safe, overturns]`` it was bisected in (relative width ``SCALE_RTOL``),
        ``pga_g`` (the record's PGA at that scale [g]) and the criterion.

    Notes
    -----
    Overturning is not monotonic in the scale (a stronger record may rock a block back):
    the scale reported is the first on the grid that overturns, refined between it and the
    grid point below, which did not.
    """
    # the records' scale search and the exact solver (numba), for the records only (#38)
    from .scaling import SCALE_GRID, least_overturning_scales

    models = [to_rocking_model(m) for m in cf.mechanisms]
    found = least_overturning_scales(models, motion, grid=SCALE_GRID if grid is None else grid)
    return [{k: v for k, v in f.items() if k != "runs"} for f in found]


def crack_patches(cand: Candidate) -> list[dict[str, Any]]:
    """Return the cracks of a candidate as planar patches through its walls.

    Returns
    -------
    list of dict
        ``wall`` (id), ``segment`` (two (s, z) points in the wall's elevation [m]) and
        ``corners`` (four world points of the patch through the wall's thickness [m]).
    """
    out = []
    for piece in cand.pieces:
        wall = piece.wall
        f = wall.frame
        ring = wall.rings[0]
        lo, hi = ring.min(axis=0) - 1.0, ring.max(axis=0) + 1.0
        for k, plane in enumerate(piece.planes):
            line = f.line_of_plane(*plane)
            if line is None:
                continue
            a, b, c = line
            # the line across the elevation's box, parametrised along its direction
            if abs(b) >= abs(a):
                p0 = np.array([lo[0], -(a * lo[0] + c) / b])
                p1 = np.array([hi[0], -(a * hi[0] + c) / b])
            else:
                p0 = np.array([-(b * lo[1] + c) / a, lo[1]])
                p1 = np.array([-(b * hi[1] + c) / a, hi[1]])
            others = [f.line_of_plane(*q) for j, q in enumerate(piece.planes) if j != k]
            for u0, u1 in segment_intervals(wall.rings, p0, p1):
                q0, q1 = p0 + u0 * (p1 - p0), p0 + u1 * (p1 - p0)
                keep = True
                for h in others:
                    if h is None:
                        continue
                    f0 = h[0] * q0[0] + h[1] * q0[1] + h[2]
                    f1 = h[0] * q1[0] + h[1] * q1[1] + h[2]
                    if f0 < 0.0 and f1 < 0.0:
                        keep = False
                        break
                    if f0 < 0.0:
                        q0 = q0 + (f0 / (f0 - f1)) * (q1 - q0)
                    elif f1 < 0.0:
                        q1 = q0 + (f0 / (f0 - f1)) * (q1 - q0)
                if not keep or float(np.hypot(*(q1 - q0))) <= 1e-9:
                    continue
                t = f.thickness
                corners = [
                    f.to_world(q0[0], 0.0, q0[1]),
                    f.to_world(q1[0], 0.0, q1[1]),
                    f.to_world(q1[0], t, q1[1]),
                    f.to_world(q0[0], t, q0[1]),
                ]
                out.append(
                    {
                        "wall": wall.id,
                        "segment": [[float(v) for v in q0], [float(v) for v in q1]],
                        "corners": [[float(v) for v in p] for p in corners],
                    }
                )
    return out


def _params_doc(cand: Candidate) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for k, v in cand.params.items():
        out[k] = v
        if k.endswith("_rad"):
            out[k[:-4] + "_deg"] = math.degrees(v)
    return out


def _band_score(values: Sequence[Optional[float]]) -> Optional[float]:
    """Geometric mean of the finite overturning accelerations over the band [g]."""
    finite = [v for v in values if v is not None and math.isfinite(v) and v > 0.0]
    if not finite or len(finite) < len(values):
        return None if not finite else float(np.exp(np.mean(np.log(finite))))
    return float(np.exp(np.mean(np.log(finite))))


def _candidate_doc(cand: Candidate, mid: str, rank: int, friction: float) -> dict[str, Any]:
    doc: dict[str, Any] = {
        "id": mid,
        "rank_static": rank,
        "family": cand.family,
        "facade": cand.facade,
        "direction": cand.direction,
        "typology": cand.typology,
        "rocking": cand.rocking,
        "parameters": _params_doc(cand),
        "bounds": {k: list(v) for k, v in cand.bounds.items()},
        "on_bound": list(cand.on_bound),
        "lam0": cand.lam0,
        "hinge_axis": [[float(v) for v in p] for p in cand.axis],
        "direction_vector": [float(v) for v in cand.direction_vector],
        "crack_planes": [
            {
                "wall": piece.wall.id,
                "point": [float(v) for v in plane[0]],
                "normal": [float(v) for v in plane[1]],
            }
            for piece in cand.pieces
            for plane in piece.planes
        ],
        "cracks": crack_patches(cand),
        "pieces": [{"wall": p.wall.id, "mass_kg": float(p.lump().mass)} for p in cand.pieces],
        "mass_kg": float(sum(p.lump().mass for p in cand.pieces)),
        "levels": [
            {
                "level": ld.level.id,
                "at_m": [float(v) for v in ld.point],
                "mass_kg": ld.mass,
                "bearing": ld.bearing,
                "thrust_N": ld.thrust,
            }
            for ld in cand.contacts
        ],
        "tie_bars": [
            {"tie_bar": t.index, "at_m": [float(v) for v in t.point], "force_N": t.tie.force}
            for t in cand.ties
        ],
        "Z_m": cand.z_base,
        "n_evaluations": cand.n_evaluations,
        "sliding": sliding_check(cand, friction),
        "notes": list(cand.notes),
    }
    if cand.lam0_negative is not None:
        doc["lam0_negative"] = cand.lam0_negative
    if cand.overburden is not None:
        doc["overburden"] = {
            "N": cand.overburden["N"],
            "x_m": cand.overburden["x"],
            "xi_from_outer_face": cand.overburden["xi"],
        }
    return doc


def _lp_doc(check: Any) -> dict[str, Any]:
    model, res = check.model, check.result
    bodies = []
    for body in res.bodies:
        ref = body[0]
        bodies.append(
            {
                "blocks": [
                    {
                        "wall": model.blocks[b].wall,
                        "rings": [r.tolist() for r in model.blocks[b].rings],
                    }
                    for b in body
                ],
                "rotation": [float(v) for v in res.velocities[ref, 3:]],
                "velocity_at_centre": [float(v) for v in res.velocities[ref, :3]],
            }
        )
    message = (
        f"the catalogue missed a mechanism: the check's multiplier {check.lam:.6g} is "
        f"{100 * check.gap:.3g} % below the best catalogue mechanism's {check.best:.6g}"
        if check.missed
        else "the best catalogue mechanism holds the check's optimum (the check's multiplier "
        f"{check.lam:.6g} is {100 * max(check.gap, 0.0):.2g} % below it)"
    )
    doc: dict[str, Any] = {
        "facade": check.facade,
        "direction": check.direction,
        "lam": check.lam,
        "best_catalogue_lam0": check.best,
        "gap": check.gap,
        "missed": check.missed,
        "threshold": MISSED_GAP,
        "message": message,
        "lam_friction": check.lam_friction,
        "sliding_governs": check.sliding,
        "status": res.status,
        "n_blocks": res.n_blocks,
        "n_rows": res.n_rows,
        "n_columns": res.n_columns,
        "lines": model.lines,
        "mechanism": bodies if check.missed else None,
    }
    if check.sliding:
        doc["sliding_note"] = (
            f"with associative friction (μ on the hinge joints) the check's multiplier drops to "
            f"{check.lam_friction:.6g}: sliding governs this façade, and the rocking-only "
            "multipliers overestimate its capacity"
        )
    return doc


def _resolve(path: str, spec_dir: Optional[Path], what: str) -> Path:
    p = Path(path)
    if not p.is_absolute() and spec_dir is not None:
        p = spec_dir / p
    if not p.is_file():
        raise InputError(f"file not found: {path} (relative to the search spec)", what)
    return p


@dataclass
class _Ranked:
    """The built candidates and their ranking (``search_run``'s middle steps)."""

    constants: Optional[ConstantsFile] = None
    failures: list[MechanismFailure] = field(default_factory=list)
    spec_file: Optional[SpecFile] = None
    envelopes: Optional[EnvelopeDocument] = None
    dynamic: list[str] = field(default_factory=list)


def _build_and_rank(
    result: SearchResult,
    keep: int,
    docs: dict[str, dict[str, Any]],
    ids: list[str],
    f_p: np.ndarray[Any, Any],
    scene_name: str,
    exact: bool,
    library: Optional[OverturningLibrary],
    mode: Optional[tuple[float, float]] = None,
) -> _Ranked:
    """Build the kept candidates and rank them by their overturning acceleration.

    ``mode`` (f_n [Hz], h_e [m]): every candidate above ground gets ``amplification
    {f_n, h_e, h = Z}``, so its envelope is the ground-level one of theory §7.3
    (``a_p,min^local / SF(f_p)``); those at ground level skip it.
    """
    out = _Ranked()
    n_built = min(keep, len(result.candidates))
    if not n_built:
        return out
    cf, out.failures, agreement, out.spec_file = build_candidates(
        result.building,
        result.candidates[:n_built],
        ids[:n_built],
        scene_name=scene_name,
        mode=mode,
    )
    for f in out.failures:
        docs[f.id]["builder"] = {"error": f.message}
    if cf is None:
        return out
    out.constants = cf
    method = "exact" if exact else "library"
    out.envelopes, _ = envelope_doc(cf, f_p, method=method, library=library)
    for entry, mech in zip(out.envelopes.mechanisms, cf.mechanisms):
        d = docs[mech.id]
        values = entry.a_p_min_g
        finite = [v for v in values if v is not None]
        d["overturning"] = {
            "a_p_min_g": values,
            "band_score_g": _band_score(values),
            "min_g": min(finite) if finite else None,
            "f_at_min_hz": float(f_p[values.index(min(finite))]) if finite else None,
        }
        if entry.amplification is not None and entry.a_p_min_local_g is not None:
            # above ground: the local envelope and Eq. 28's SF(f_p) it was divided by
            d["amplification"] = entry.amplification.model_dump()
            d["overturning"]["a_p_min_local_g"] = entry.a_p_min_local_g
            d["overturning"]["scale_factor"] = entry.scale_factor
            d["overturning"]["band_score_local_g"] = _band_score(entry.a_p_min_local_g)
            d["overturning"]["sf_formula"] = (
                "SF(f_p) = sqrt(1 + (R(f_p/f_n) h/h_e)^2), R the 5 % pulse response spectrum "
                "(theory §7.1, Eq. 28)"
            )
        a = agreement.get(mech.id, {})
        d["builder"] = {
            "lam0": a.get("lam0"),
            "lam0_rel": a.get("lam0_rel"),
            "mass_rel": a.get("mass_rel"),
            "agrees": a.get("agrees"),
            "tolerance": AGREEMENT_RTOL,
        }
        d["lam_linearised"] = mech.positive.lam
        d["constants"] = {
            "positive": mech.positive.model_dump(exclude_none=True),
            "negative": None
            if mech.negative is None
            else mech.negative.model_dump(exclude_none=True),
            "eta": mech.eta,
            "eta_source": mech.eta_source,
        }
        if a and not a.get("agrees"):
            d["notes"].append(
                f"the builder's exact λ0 ({a.get('lam0')}) and mass differ from the search's by "
                f"{a.get('lam0_rel'):.3g} and {a.get('mass_rel'):.3g} (relative): an idealised "
                "wall or a level the builder places elsewhere; the ranking uses the builder's "
                "constants"
            )

    def score(mid: str) -> float:
        s = docs[mid]["overturning"]["band_score_g"]
        return math.inf if s is None else float(s)

    # near-ties in the band score go by the static rank (the order of the built mechanisms)
    built = [m.id for m in cf.mechanisms]
    out.dynamic = [built[k] for k in rank_order([score(mid) for mid in built])]
    for r, mid in enumerate(out.dynamic):
        docs[mid]["rank_dynamic"] = r + 1
    return out


def _run_records(
    cf: ConstantsFile, top: list[str], motions: Sequence[Any], docs: dict[str, dict[str, Any]]
) -> list[dict[str, Any]]:
    """Each record's smallest scale factor that overturns each top mechanism.

    A mechanism above ground (``amplification``) receives the record times Eq. 28's
    ``SF = sqrt(1 + (S_a(1/f_n)/a_g h/h_e)^2)`` (theory §7.3, the record's own 5 % spectrum,
    ``scaling.mechanism_scale_factor``): SF does not depend on the record's scale, so the
    ground scale that overturns it is the local one over SF (``scale``; the local one is
    ``scale_local``). Mechanisms at ground level take the record as it is.
    """
    # Eq. 28's scale factor of a record (its spectrum), for the records only
    from .scaling import mechanism_scale_factor

    out: list[dict[str, Any]] = []
    sub = ConstantsFile(mechanisms=[m for m in cf.mechanisms if m.id in top])
    for motion in motions:
        try:
            runs = scales_to_overturn(sub, motion)
            factors = [mechanism_scale_factor(m, motion, "eq28") for m in sub.mechanisms]
        except RockmechError as exc:
            out.append({"record": motion.name, "note": f"not run: {exc}"})
            continue
        out.append({"record": motion.name, "pga_g": float(motion.pga_g), "dt": float(motion.dt)})
        for mech, run, info in zip(sub.mechanisms, runs, factors):
            if info is not None:
                sf = float(info["value"])
                local = run
                run = {**run, "scale_local": local["scale"], "scale_factor": info}
                if local["scale"] is not None:
                    run["scale"] = local["scale"] / sf
                    run["bracket"] = [v / sf for v in local["bracket"]]
                    run["pga_g"] = local["pga_g"] / sf
            docs[mech.id].setdefault("records", []).append({"record": motion.name, **run})
    return out


def _run_check(
    cf: ConstantsFile,
    top: list[str],
    site: Any,
    docs: dict[str, dict[str, Any]],
) -> dict[str, Any]:
    """Run the code check of the top mechanisms (α0 and the verdict beside the dynamics).

    Each mechanism is checked at its Z: with ``amplification`` on the floor spectrum there
    (Circ. 2019 §C7.2.3); without building data a mechanism above ground gets its Z all the
    same, so that its check says it is incomplete (as ``rockmech check``) rather than pass
    on the ground's spectrum.
    """
    heights = {
        mid: float(docs[mid]["Z_m"])
        for mid in top
        if docs[mid]["Z_m"] > 0.0 and "amplification" not in docs[mid]
    }
    # the code check, for a search with a site only (#37)
    from .assess import check_doc

    sub = ConstantsFile(mechanisms=[m for m in cf.mechanisms if m.id in top])
    check = check_doc(sub, site, heights)
    for row in check["mechanisms"]:
        lin = row["linear"]
        docs[row["id"]]["code_check"] = {
            "alpha0": lin.get("alpha0"),
            "passes": row["passes"],
            "linear": lin,
            "nonlinear": row["nonlinear"],
            "Z": row["Z"],
            "Z_source": row["Z_source"],
            "T1": row["T1"],
            "T1_source": row["T1_source"],
        }
    return {"site": check["site"], "governing": check["governing"]}


def _compare(
    docs: list[dict[str, Any]], dynamic: list[str], band: Sequence[float]
) -> dict[str, Any]:
    """Where the static (λ0) and the dynamic rankings of the built mechanisms differ."""
    built = set(dynamic)
    static = [d["id"] for d in docs if d["id"] in built]
    by_id = {d["id"]: d for d in docs}
    differences = []
    for mid in dynamic:
        rs, rd = static.index(mid) + 1, dynamic.index(mid) + 1
        if rs != rd:
            differences.append({"id": mid, "static": rs, "dynamic": rd})
    summary = []
    if dynamic and dynamic[0] != static[0]:
        summary.append(
            f"the static and the dynamic rankings differ: {static[0]} has the least λ0 "
            f"({by_id[static[0]]['lam0']:.4g}), {dynamic[0]} the least overturning "
            f"acceleration over {band[0]:g}-{band[1]:g} Hz "
            f"({by_id[dynamic[0]]['overturning']['band_score_g']:.4g} g)"
        )
    return {"differences": differences, "summary": summary}


def _input_doc(
    scene: Any, spec: SearchSpec, bld: Any, scene_name: str, spec_name: str
) -> dict[str, Any]:
    return {
        "scene": scene_name,
        "spec": spec_name,
        "scene_units": getattr(scene, "units", None),
        "walls": {
            w.id: {
                "object": w.selector,
                "thickness_m": w.frame.thickness,
                "length_m": w.length,
                "height_m": w.z_hi - w.z_lo,
                "exact_prism": w.exact,
                "openings": len(w.holes),
                "facade": w.is_facade,
            }
            for w in bld.walls.values()
        },
        "junctions": [
            {
                "facade": a,
                "wall": r.wall.id,
                "end": r.end,
                "connection": r.connection,
                "beta_bond_rad": r.beta_bond,
                "corner": r.corner,
            }
            for a, rets in bld.returns.items()
            for r in rets
        ],
        "families": list(spec.families),
        "directions": list(spec.directions),
        "friction": spec.friction,
    }


#: What every search assumes, stated in its document.
ASSUMPTIONS = (
    "single-degree-of-freedom mechanisms only; rocking with infinite friction at the hinge "
    "joints (the sliding flags say where friction would not hold)",
    "a crack through a return wall separates its wedge without friction (the macro-block "
    "model); good connections make it run at least at the bond angle",
)


def _height_assumption(info: dict[str, Any]) -> str:
    """Return the document's assumption on where the mechanisms are ranked."""
    if not info["given"]:
        return NO_BUILDING_DATA
    return (
        "each mechanism is ranked where it sits: one above ground (Z > 0) on the motion "
        f"amplified by the building's first mode (f_n = {info['f_n_hz']:.4g} Hz, from "
        f"{info['T1_source']}; h_e = {info['h_e_m']:.4g} m, from {info['h_e_source']}) by "
        "Eq. 28 (theory §7), records likewise, and the code check on the floor spectrum at Z "
        "(Circ. 2019 §C7.2.3); one at ground level on the ground motion"
    )


def _search_spec(spec: Any, source: str) -> SearchSpec:
    """Return a search spec given as a ``SearchSpec`` or a dict (validated as a file is)."""
    if isinstance(spec, SearchSpec):
        return spec
    if isinstance(spec, dict):
        try:
            text = json.dumps(spec, allow_nan=False)
        except (TypeError, ValueError) as exc:
            raise InputError(
                f"a spec given as a dict holds JSON values only: {exc}", "spec"
            ) from None
        return parse_search_spec(text, source)
    hint = "; read a file with rockmech.read_search_spec(path)" if is_path(spec) else ""
    raise InputError(
        f"must be a SearchSpec or a dict of its fields, got {type(spec).__name__}{hint}", "spec"
    )


def _scene_object(scene: Any) -> BaseScene:
    """Return ``scene`` if it is a scene read by ``read_scene``; else say what to pass."""
    if isinstance(scene, BaseScene):
        return scene
    hint = (
        "; read the file with rockmech.read_scene(path), or give rockmech.search(scene, spec) "
        "the paths"
        if is_path(scene)
        else ""
    )
    raise InputError(
        f"must be a scene (rockmech.read_scene), got {type(scene).__name__}{hint}", "scene"
    )


def _read_site(path: Path) -> SiteFile:
    """Read a site file (``assess.read_site``, loaded here: only a search with a site needs it)."""
    # the site reader lives with the code check (workflows.assess)
    from .assess import read_site

    return read_site(path)


def _read_record(path: Path) -> Any:
    """Read a record (``inputs.read_record``, loaded here: only a search with records needs it)."""
    # the record readers (and the CAD inputs beside them), for records only
    from .inputs import read_record

    return read_record(path)


def _site_object(site: Any, field_name: str) -> Any:
    """Return a site given as a ``SiteFile``, or read it from a site file's path."""
    if site is None or isinstance(site, SiteFile):
        return site
    return _read_site(as_path(site, field_name, "a SiteFile or " + PATH_TYPES))


def _motion_objects(motions: Any, field_name: str) -> Optional[list[Any]]:
    """Return records given as ``GroundMotion`` objects, or read them from their paths."""
    if motions is None:
        return None
    # the record type, for a search given records only
    from ..core.records import GroundMotion

    if is_path(motions) or isinstance(motions, GroundMotion):
        raise InputError(
            "must be a sequence of records (GroundMotion objects or paths), got one record; "
            "give a list of it ([record])",
            field_name,
        )
    out = []
    for k, m in enumerate(motions):
        where = f"{field_name}[{k}]"
        out.append(
            m
            if isinstance(m, GroundMotion)
            else _read_record(as_path(m, where, "a GroundMotion or " + PATH_TYPES))
        )
    return out


def search_run(
    scene: Any,
    spec: Union[SearchSpec, dict[str, Any]],
    *,
    scene_name: str = "scene",
    spec_name: str = "search spec",
    spec_dir: Optional[PathLike] = None,
    site: Any = None,
    motions: Optional[Sequence[Any]] = None,
    exact: bool = False,
    library: Optional[OverturningLibrary] = None,
    max_evaluations: Optional[int] = MAX_EVALUATIONS,
    max_lp_blocks: Optional[int] = MAX_LP_BLOCKS,
    max_built: Optional[int] = None,
) -> SearchRun:
    """Search, build and rank a scene's mechanisms (the module docstring's steps).

    Parameters
    ----------
    scene : BaseScene
        The scene (``cad_maths.scenes.read_scene``).
    spec : SearchSpec or dict
        The search spec (``read_search_spec``), or a dict of its fields, validated as a file
        is (errors name ``spec_name`` and the field).
    scene_name, spec_name : str
        For the document's provenance.
    spec_dir : str or os.PathLike, optional
        Folder of the spec: its ``ranking.site`` and ``ranking.records`` are relative to it.
    site : SiteFile, str or os.PathLike, optional
        The site for the code check (default: the spec's ``ranking.site``).
    motions : sequence of GroundMotion, str or os.PathLike, optional
        Records (default: the spec's ``ranking.records``).
    exact : bool
        Envelopes by the exact solver instead of the library.
    library : OverturningLibrary, optional
        The library to interpolate (default: the shipped one).
    max_evaluations, max_lp_blocks : int or None
        Work limits (``MAX_EVALUATIONS``, ``MAX_LP_BLOCKS``; None: none): a search that
        would exceed one stops before doing that work (``InputError`` on ``work_limit``).
    max_built : int, optional
        Most mechanisms built and ranked (the service's ``max_mechanisms``), below the spec's
        ``candidates.keep``; the document says when it cut the list.

    Returns
    -------
    SearchRun

    Raises
    ------
    InputError
        A scene that is not one, a spec that is neither a ``SearchSpec`` nor a valid dict, a
        path that is not ``str`` or ``os.PathLike``, a missing or unreadable file.
    """
    t0 = time.perf_counter()
    scene = _scene_object(scene)
    spec = _search_spec(spec, spec_name)
    folder = None if spec_dir is None else readable_folder(spec_dir, "spec_dir")
    site = _site_object(site, "site")
    motions = _motion_objects(motions, "motions")
    rk = spec.ranking
    if site is None and rk.site is not None:
        site = _read_site(_resolve(rk.site, folder, "ranking.site"))
    if motions is None:
        motions = [
            _read_record(_resolve(r, folder, f"ranking.records[{k}]"))
            for k, r in enumerate(rk.records)
        ]
    check_first_mode(spec, site)  # before the search: a contradiction costs nothing
    result = run_search(scene, spec, max_evaluations=max_evaluations, max_lp_blocks=max_lp_blocks)
    mode_info = first_mode(spec, site, result.building)
    mode = (mode_info["f_n_hz"], mode_info["h_e_m"]) if mode_info["given"] else None
    t1 = time.perf_counter()
    cands = result.candidates
    ids = _ids(len(cands))
    f_p = log_grid(
        rk.band_hz[0], rk.band_hz[1], rk.n_frequencies, names=("band_hz[0]", "band_hz[1]")
    )
    docs = [_candidate_doc(c, ids[k], k + 1, spec.friction) for k, c in enumerate(cands)]
    by_id = {d["id"]: d for d in docs}
    keep = spec.candidates.keep
    notes = list(result.notes)
    if max_built is not None and min(keep, len(cands)) > max_built:
        notes.append(
            f"only the {max_built} mechanisms of least λ0 are built and ranked (the service's "
            f"max_mechanisms), not the {min(keep, len(cands))} candidates.keep asks for"
        )
        keep = max_built
    ranked = _build_and_rank(result, keep, by_id, ids, f_p, scene_name, exact, library, mode)
    t2 = time.perf_counter()
    top = ranked.dynamic[: rk.keep]
    cf = ranked.constants
    records = _run_records(cf, top, motions, by_id) if cf is not None and top and motions else []
    t3 = time.perf_counter()
    check = (
        _run_check(cf, top, site, by_id) if cf is not None and top and site is not None else None
    )
    t4 = time.perf_counter()
    compare = _compare(docs, ranked.dynamic, rk.band_hz)
    env = ranked.envelopes
    n_built = 0 if cf is None else len(cf.mechanisms)
    doc: dict[str, Any] = {
        "kind": "search",
        "input": _input_doc(scene, spec, result.building, scene_name, spec_name),
        "band": {"f_p": [float(v) for v in f_p], "band_hz": list(rk.band_hz)},
        "candidates": docs,
        "rankings": {
            "static": [d["id"] for d in docs],
            "dynamic": ranked.dynamic,
            **compare,
            "governing": env.governing if env else [],
            "critical": [b.to_dict() for b in env.critical] if env else [],
            "envelope_method": env.method.to_dict() if env else None,
            "band_score": "geometric mean of a_p,min over the band [g]",
        },
        "lp": [_lp_doc(ch) for ch in result.checks],
        "records": records,
        "code_check": check,
        "not_built": [d["id"] for d in docs[min(keep, len(docs)) :]],
        "failures": [{"id": f.id, "error": f.message} for f in ranked.failures],
        "counts": {**result.counts, "built": n_built},
        "timings": {
            **result.timings,
            "constants_and_ranking_s": t2 - t1,
            "records_s": t3 - t2,
            "code_check_s": t4 - t3,
            "total_s": t4 - t0,
        },
        "building": mode_info,
        "assumptions": [*ASSUMPTIONS, _height_assumption(mode_info)],
        # issue #36: a density of 1.8 (t/m^3?) was a note among ten; a warning, as in a spec
        "warnings": spec.plausibility_notes(),
        "notes": notes + mode_info["notes"] + compare["summary"],
    }
    typed = SearchDocument.model_validate(stamp(doc, "search"))
    return SearchRun(typed, ranked.spec_file, cf, result, dict(enumerate(ids)))


def _layer(model: Any, r3: Any, path: str, cache: dict[str, int]) -> int:
    """Index of a layer given by its full path ``A::B``, made (with its parents) on first use."""
    if path in cache:
        return cache[path]
    parent = ""
    parent_id = None
    for part in path.split("::"):
        full = f"{parent}::{part}" if parent else part
        if full not in cache:
            layer = r3.Layer()
            layer.Name = part
            if parent_id is not None:
                layer.ParentLayerId = parent_id
            cache[full] = model.Layers.Add(layer)
        parent_id = model.Layers.FindIndex(cache[full]).Id
        parent = full
    return cache[path]


def search_3dm(run: SearchRun) -> bytes:
    """Encode the search's scene (walls, levels, tie-bars [m]) and its crack layer as ``.3dm``.

    Objects keep their ids, names and layers, so the selectors of ``search.spec.json`` find
    them; each built mechanism has a layer ``rockmech search::<id>`` with its cracks (planar
    patches through the walls) and its hinge axis.
    """
    r3 = require("rhino3dm", "geometry", "to write the search's .3dm")
    model = r3.File3dm()
    model.Settings.ModelUnitSystem = r3.UnitSystem.Meters
    tol = float(run.result.building.scene.tolerance or 0.0)
    model.Settings.ModelAbsoluteTolerance = tol if tol > 0.0 else 1e-4
    layers: dict[str, int] = {}
    for obj in run.result.building.scene.objects:
        attrs = r3.ObjectAttributes()
        attrs.Name = obj.name
        attrs.Id = obj.id
        attrs.LayerIndex = _layer(model, r3, obj.layer or "rockmech search::scene", layers)
        geo = obj.geometry
        if isinstance(geo, tuple):
            model.Objects.AddLine(r3.Point3d(*geo[0]), r3.Point3d(*geo[1]), attrs)
            continue
        mesh = r3.Mesh()
        for x, y, z in geo.vertices.tolist():
            mesh.Vertices.AddPoint3d(x, y, z)
        for a, b, c in geo.faces.tolist():
            mesh.Faces.AddFace(a, b, c)
        model.Objects.AddMesh(mesh, attrs)
    built = set() if run.constants is None else {m.id for m in run.constants.mechanisms}
    for k, cand in enumerate(run.result.candidates):
        mid = run.ids[k]
        if mid not in built:
            continue
        index = _layer(model, r3, f"rockmech search::{mid}", layers)
        for j, crack in enumerate(run.doc.find(mid).cracks):
            attrs = r3.ObjectAttributes()
            attrs.Name = f"{mid} crack {j + 1} ({crack.wall})"
            attrs.LayerIndex = index
            mesh = r3.Mesh()
            for x, y, z in crack.corners:
                mesh.Vertices.AddPoint3d(x, y, z)
            mesh.Faces.AddFace(0, 1, 2, 3)
            model.Objects.AddMesh(mesh, attrs)
        attrs = r3.ObjectAttributes()
        attrs.Name = f"{mid} hinge axis"
        attrs.LayerIndex = index
        a, b = cand.axis
        if cand.family == "corner":
            b = a + 2.0 * (b - a)
        model.Objects.AddLine(r3.Point3d(*a), r3.Point3d(*b), attrs)
    return _encode(model)


def _encode(model: Any) -> bytes:
    """Write a File3dm to bytes (Rhino 8 format) through a temporary file."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "search.3dm"
        if not model.Write(str(path), 8):
            raise InputError("rhino3dm could not write the search's .3dm", "out")
        return path.read_bytes()


def write_search_files(run: SearchRun, out_dir: Path, *, figure: bool = True) -> list[Path]:
    """Write a search's files into a folder (``run_folder`` stages it; each written whole).

    Returns
    -------
    list of Path
        ``search.json``, ``search.spec.json``, ``constants.json`` (when any was built),
        ``search.3dm`` and ``search.png``.
    """
    out = []
    path = out_dir / "search.json"
    write_atomic(path, json.dumps(run.doc.to_dict(), indent=1, allow_nan=False) + "\n")
    out.append(path)
    if run.spec_file is not None:
        path = out_dir / "search.spec.json"
        spec = run.spec_file.model_copy(update={"rockmech_version": __version__})
        text = spec.model_dump_json(indent=1, exclude_none=True)
        write_atomic(path, text + "\n")
        out.append(path)
    if run.constants is not None:
        path = out_dir / "constants.json"
        write_constants(stamped(run.constants), path)
        out.append(path)
    path = out_dir / "search.3dm"
    write_atomic(path, search_3dm(run))
    out.append(path)
    if figure:
        # matplotlib, for the figure only (#37)
        from ..report.search_figure import plot_search

        png = plot_search(run, out_dir / "search.png")
        if png is not None:
            out.append(png)
    return out


def write_search(run: SearchRun, out: PathLike, *, figure: bool = True) -> list[Path]:
    """Write a search's files into the folder ``out`` as ``rockmech search --out`` does.

    Through ``rundir.run_folder``: only rockmech's own outputs in ``out`` are replaced, as
    one set; every other file there stays as it was.

    Parameters
    ----------
    run : SearchRun
        The search (``rockmech.search``; ``search_from_files``, ``search_run``).
    out : str or os.PathLike
        The folder (created if missing).
    figure : bool
        Also draw ``search.png``.

    Returns
    -------
    list of Path
        The files written, in ``out`` (as ``write_search_files``).
    """
    if not isinstance(run, SearchRun):
        raise wrong_type(run, "run", "a SearchRun", "rockmech.search(scene, spec) gives one")
    out = as_path(out, "out")
    notes: list[str] = []
    with run_folder(out, on_note=notes.append, command="search") as tmp:
        names = [p.name for p in write_search_files(run, tmp, figure=figure)]
    for note in notes:
        warnings.warn(note, UserWarning, stacklevel=2)
    return [Path(out) / name for name in names]


def search_from_files(
    scene: PathLike,
    spec: PathLike,
    *,
    units: Optional[str] = None,
    site: Optional[PathLike] = None,
    records: Sequence[PathLike] = (),
    exact: bool = False,
    limits: bool = True,
) -> SearchRun:
    """Search a scene file with a search-spec file (the command line's and the API's way in).

    Parameters
    ----------
    scene : str or os.PathLike
        A ``.3dm`` file, or a scan mesh (``.ply``, ``.obj``, ``.stl``, ``.off``) with ``units``.
    spec : str or os.PathLike
        The search spec (JSON); its ``ranking.site`` and ``ranking.records`` are relative to
        its folder.
    units : str, optional
        Length unit of a scan mesh.
    site : str or os.PathLike, optional
        A site file, instead of the spec's ``ranking.site``.
    records : sequence of str or os.PathLike
        Records, instead of the spec's ``ranking.records`` (formats detected).
    exact : bool
        Envelopes by the exact solver instead of the library.
    limits : bool
        Apply the work limits (``MAX_EVALUATIONS``, ``MAX_LP_BLOCKS``).
    """
    scene_path = check_file(scene, "scene")
    spec_path = as_path(spec, "spec")
    search_spec = read_search_spec(spec_path)
    scene_obj = read_scene(scene_path, units=units)
    site_obj = None if site is None else _read_site(as_path(site, "site"))
    motions = _motion_objects(records, "records")
    return search_run(
        scene_obj,
        search_spec,
        scene_name=scene_path.name,
        spec_name=spec_path.name,
        spec_dir=spec_path.parent,
        site=site_obj,
        motions=motions or None,
        exact=exact,
        max_evaluations=MAX_EVALUATIONS if limits else None,
        max_lp_blocks=MAX_LP_BLOCKS if limits else None,
    )
