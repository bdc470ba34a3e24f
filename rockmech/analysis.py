"""The analyses a script runs, one function each, as the ``rockmech`` command runs them.

Every function calls the workflow the command line and the REST service call, so a script,
the command line and the service give the same numbers; each returns the command's typed document
(``shared_schema.documents``; ``to_dict()`` is the JSON the command prints). Inputs may
be given as objects (``ConstantsFile``, ``GroundMotion``, ``SiteFile``) or as file paths,
each a ``str`` or an ``os.PathLike`` (``pathlib.Path``); a JSON document (constants, a site,
a retrofit or search spec) also as an open file (``shared_schema.paths.read_source``). A
missing file, a folder or an argument of another type is an ``InputError`` naming the
argument (and the path).

SI units, except where a name says otherwise (``a_p_g`` in g).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, Optional, Union

import numpy as np

from shared_schema.constants import ConstantsFile
from shared_schema.documents.assess import AssessDocument
from shared_schema.documents.check import CheckDocument
from shared_schema.documents.envelope import EnvelopeDocument
from shared_schema.documents.history import HistoryDocument
from shared_schema.documents.ida import IdaDocument
from shared_schema.errors import InputError, wrong_type
from shared_schema.paths import (
    PATH_TYPES,
    SOURCE_TYPES,
    PathLike,
    Source,
    as_path,
    is_file_object,
    is_path,
    readable_file,
)
from shared_schema.retrofit import RetrofitDoc, RetrofitSpec, read_retrofit_spec
from shared_schema.site import SiteFile
from solver_service.core.exact import simulate
from solver_service.core.excitation import Pulse
from solver_service.core.model import RockingModel
from solver_service.core.records import GroundMotion
from solver_service.core.result import RockingResult
from solver_service.workflows import assess as _assess
from solver_service.workflows import inputs as _inputs
from solver_service.workflows.adapter import models_from_file
from solver_service.workflows.documents import envelope_doc, frequency_grid, history_doc
from solver_service.workflows.ida import run_ida
from solver_service.workflows.retrofit import retrofit_doc
from solver_service.workflows.retrofit_records import read_retrofit_records
from solver_service.workflows.scaling import Building

if TYPE_CHECKING:  # the search's types; its workflow is imported when a search runs
    from cad_maths.scene_base import BaseScene
    from shared_schema.search import SearchSpec
    from solver_service.workflows.search import SearchRun

__all__ = [
    "assess",
    "check",
    "constants_from_scene",
    "envelope",
    "history",
    "ida",
    "models_from_constants",
    "pulse",
    "read_constants",
    "read_record",
    "read_site",
    "retrofit",
    "search",
]

#: Constants given as an object or as a file (JSON, or a ``.csv``/``.xlsx`` table); an open
#: file is read as JSON.
Constants = Union[ConstantsFile, Source]
#: A site given as an object or as a file (a path or an open file).
Site = Union[SiteFile, Source]
#: A record given as an object or as a file (format detected; a two-column file in g).
Record = Union[GroundMotion, PathLike]


def read_constants(path: Source) -> ConstantsFile:
    """Read and validate a kinematic-constants file (JSON) or a constants table.

    Parameters
    ----------
    path : str, Path or open file
        A ``.json`` constants file (a path, or an open file: ``open(p, "rb")``,
        ``io.BytesIO``), or the path of a ``.csv``/``.xlsx`` table with one mechanism per row
        (``.xlsx`` needs the ``tables`` extra): ``id``, ``rocking``, ``p_eq`` [rad/s],
        ``lam`` [-], ``eta`` [-], optional ``phi_ov`` [rad], ``f_n`` [Hz], ``h_e`` [m],
        ``h`` [m], ... (units in the column titles).

    Returns
    -------
    ConstantsFile
        Every mechanism with its constants per side (``mech.positive.p_eq`` [rad/s],
        ``.lam`` [-], ``.phi_ov`` [rad]).
    """
    return _inputs.read_constants(path)


def constants_from_scene(
    scene: PathLike, spec: PathLike, units: Optional[str] = None
) -> ConstantsFile:
    """Kinematic constants of every mechanism of a spec from the solids of a scene.

    Needs the ``geometry`` extra (``pip install 'rockmech[geometry]'``).

    Parameters
    ----------
    scene : str or Path
        A Rhino ``.3dm`` file, or a scan mesh (``.ply``, ``.obj``, ``.stl``, ``.off``).
    spec : str or Path
        The mechanism spec (JSON); relative paths in it are taken from its folder.
    units : {"mm", "cm", "m", "in", "ft"}, optional
        Length unit of a scan mesh (required there; a ``.3dm`` states its own).

    Returns
    -------
    ConstantsFile
    """
    return _inputs.constants_from_scene_files(as_path(scene, "scene"), as_path(spec, "spec"), units)


def _constants(constants: Constants) -> ConstantsFile:
    if isinstance(constants, ConstantsFile):
        return constants
    if not is_file_object(constants):
        as_path(constants, "constants", "a ConstantsFile or " + SOURCE_TYPES)
    return read_constants(constants)


def models_from_constants(constants: Constants) -> list[RockingModel]:
    """Return the solver's models of every mechanism of a constants file.

    Parameters
    ----------
    constants : ConstantsFile, str, Path or open file
        The constants, or a constants file or table to read.

    Returns
    -------
    list of RockingModel
        One per mechanism, in the file's order (``model.positive.p_eq`` [rad/s], ``.lam``
        [-], ``.phi_ov`` [rad]; ``model.eta`` [-]), ready for ``simulate`` and ``pulse``.
    """
    return models_from_file(_constants(constants))


def read_record(
    path: PathLike,
    *,
    format: Optional[str] = None,
    units: Optional[str] = None,
    dt: Optional[float] = None,
    channel: Union[int, str, None] = None,
    component: Optional[str] = None,
) -> GroundMotion:
    """Read a ground-motion record as ``rockmech`` does.

    Parameters
    ----------
    path : str or Path
        PEER AT2, ESM/ITACA, K-NET/KiK-net, COSMOS V2, CSMIP/DMG V2, GeoNet V2A,
        two-column (t [s], a), one-column (with ``dt``) or CSV.
    format : str, optional
        The format (default: detected from the content).
    units : {"g", "m/s2", "cm/s2", "mm/s2", "mg", "in/s2"}, optional
        Acceleration units of a file that does not state them (a two-column file: g).
    dt : float, optional
        Sampling interval [s] of a record without a time column.
    channel, component : optional
        The channel of a file with several (DMG V2, GeoNet V2A).

    Returns
    -------
    GroundMotion
        ``accel`` [m/s²] at ``dt`` [s]; ``pga_g`` [g]; ``warnings`` (implausible values).
    """
    return _inputs.read_record(as_path(path, "record"), format, units, dt, channel, component)


def _numbers(values: Sequence[float], field: str) -> list[float]:
    """Return a sequence of numbers as floats; refuse one number, a str or another type."""
    if isinstance(values, (str, bytes)) or not isinstance(values, (Sequence, np.ndarray)):
        hint = f"give a list of it: [{values!r}]" if isinstance(values, (int, float)) else ""
        raise wrong_type(values, field, "a sequence of numbers", hint)
    out = []
    for k, value in enumerate(values):
        if isinstance(value, bool) or not isinstance(value, (int, float, np.number)):
            raise wrong_type(value, f"{field}[{k}]", "a number")
        out.append(float(value))
    return out


def _record(record: Record, field: str = "record") -> GroundMotion:
    if isinstance(record, GroundMotion):
        return record
    return read_record(as_path(record, field, "a GroundMotion or " + PATH_TYPES))


def _records(records: Sequence[Record]) -> list[GroundMotion]:
    # one path (a str is a sequence of characters) or one record where a list belongs
    if is_path(records) or isinstance(records, GroundMotion):
        raise InputError(
            "must be a sequence of records (GroundMotion objects or paths), got one record; "
            "give a list of it ([record])",
            "records",
        )
    return [_record(r, f"records[{k}]") for k, r in enumerate(records)]


def read_site(path: Source) -> SiteFile:
    """Read and validate a site file (NTC 2018 or EC8 hazard, FC, q, the building).

    Parameters
    ----------
    path : str, Path or open file
        The site JSON file.

    Returns
    -------
    SiteFile
    """
    return _assess.read_site(path)


def _site(site: Site) -> SiteFile:
    if isinstance(site, SiteFile):
        return site
    if not is_file_object(site):
        as_path(site, "site", "a SiteFile or " + SOURCE_TYPES)
    return read_site(site)


def pulse(
    model: RockingModel,
    a_p_g: float,
    f_p: float,
    *,
    shape: str = "sine",
    criterion: Optional[str] = None,
) -> RockingResult:
    """Response of one mechanism to a one-cycle pulse (exact integration).

    Parameters
    ----------
    model : RockingModel
        The mechanism (``RockingModel.symmetric`` or one of ``models_from_constants``);
        needs ``eta``.
    a_p_g : float
        Signed pulse amplitude [g]; > 0 first pushes towards negative rotation (Housner).
    f_p : float
        Pulse frequency [Hz].
    shape : {"sine", "cosine"}
        Pulse shape.
    criterion : {"exact", "ratio"}, optional
        The verdict (default for pulses: ``exact``, the body cannot come back).

    Returns
    -------
    RockingResult
        ``overturned``, ``peak_ratio`` (max ``|phi|/phi_ov`` [-]), ``t_overturn`` [s],
        ``n_impacts``, ``error_estimate`` [-], ``runtime_s`` [s].
    """
    return simulate(model, Pulse.from_g(a_p_g, f_p=f_p, shape=shape), criterion=criterion)


def history(
    constants: Constants,
    record: Record,
    scales: Sequence[float] = (1.0,),
    *,
    sf: str = "none",
    building_height: Optional[float] = None,
    criterion: Optional[str] = None,
    at_height: Optional[float] = None,
) -> HistoryDocument:
    """Time histories of every mechanism at every scale factor of a record.

    As ``rockmech history --json``.

    Parameters
    ----------
    constants : ConstantsFile, str, Path or open file
        The mechanisms (each needs ``eta``; one without it is listed in ``skipped``).
    record : GroundMotion, str or Path
        The record (a file is read with ``read_record``'s defaults).
    scales : sequence of float
        Scale factors on the record [-], each > 0.
    sf : {"none", "eq28", "ec8", "nzs"}
        Scale factor up the structure for mechanisms with ``amplification`` data.
    building_height : float, optional
        Height of the building [m] (``ec8``, ``nzs``).
    criterion : {"ratio", "exact"}, optional
        The verdict (default for records: ``ratio``, ``|phi|/phi_ov >= 1``).
    at_height : float, optional
        Also give each run's peak displacement this far [m] above the rotation axis.

    Returns
    -------
    HistoryDocument
        The document ``rockmech history --json`` prints (``to_dict()``): in ``results``
        one ``HistoryRow`` per mechanism and scale (``peak_ratio`` [-], ``overturned``,
        ``t_overturn`` [s], ``n_impacts``, ``error_estimate`` [-]); ``find(id, scale)``
        returns one; ``skipped`` the mechanisms left out.
    """
    return history_doc(
        _constants(constants),
        _record(record),
        _numbers(scales, "scales"),
        sf=sf,
        building=Building(building_height),
        criterion=criterion,
        at_height=at_height,
    )


def envelope(
    constants: Constants,
    *,
    f_min: float = 0.1,
    f_max: float = 10.0,
    n: int = 200,
    fast: bool = False,
) -> EnvelopeDocument:
    """Overturning envelopes of every mechanism and the critical bands.

    As ``rockmech envelope --json``: the smallest one-sine pulse amplitude at the ground that
    overturns each mechanism, at ``n`` log-spaced pulse frequencies.

    Parameters
    ----------
    constants : ConstantsFile, str, Path or open file
        The mechanisms.
    f_min, f_max : float
        Frequency range [Hz], ``0 < f_min < f_max``.
    n : int
        Number of frequencies.
    fast : bool
        The fast mode: interpolate the overturning library (exact where it cannot interpolate
        safely; never above the exact value, at most 5 % below) instead of the exact
        integrator at every frequency (the default, as on every other path).

    Returns
    -------
    EnvelopeDocument
        The document ``rockmech envelope --json`` prints (``to_dict()``): ``f_p`` [Hz],
        per mechanism its ``a_p_min_g`` [g] (``find(id)``), the ``critical`` bands and
        ``critical_at(f_p)``.
    """
    method = "library" if fast else "exact"
    doc, _ = envelope_doc(_constants(constants), frequency_grid(f_min, f_max, n), method=method)
    return doc


def ida(
    constants: Constants,
    records: Sequence[Record],
    levels: Sequence[float],
    *,
    measure: str = "scale",
    sf: str = "none",
    building_height: Optional[float] = None,
    criterion: Optional[str] = None,
    scheduler: Optional[str] = None,
    jobs: Optional[int] = None,
) -> IdaDocument:
    """Incremental dynamic analysis: overturned fraction per level and a fragility fit.

    As ``rockmech ida``.

    Parameters
    ----------
    constants : ConstantsFile, str, Path or open file
        The mechanisms (each needs ``eta``).
    records : sequence of GroundMotion, str or Path
        The records, at least one.
    levels : sequence of float
        Intensity levels, each > 0: scale factors [-] (``measure="scale"``) or PGAs [g]
        (``measure="pga"``).
    measure : {"scale", "pga"}
        The intensity measure (``IdaDocument.measure``, ``rockmech ida --measure``).
    sf, building_height, criterion
        As ``history``.
    scheduler : str, optional
        A dask.distributed scheduler's address (``tcp://host:8786``; the ``dask`` extra).
    jobs : int, optional
        Threads of a local run (default: every core this process may use).

    Returns
    -------
    IdaDocument
        The document ``rockmech ida --json`` prints (``to_dict()``): its ``measure`` and
        ``levels``, and per mechanism (``find(id)``) the ``fraction`` of the records that
        overturn it at each level [-] and its ``fragility`` (``median`` in the measure's
        units, ``beta`` [-], ``note``).
    """
    return run_ida(
        _constants(constants),
        _records(records),
        _numbers(levels, "levels"),
        measure=measure,
        sf=sf,
        building=Building(building_height),
        criterion=criterion,
        scheduler=scheduler,
        jobs=jobs,
    )


def check(constants: Constants, site: Site) -> CheckDocument:
    """NTC 2018 / Circolare 2019 §C8.7.1 kinematic checks of every mechanism on a site.

    As ``rockmech check --json``; mechanisms need ``virtual_work`` per side.

    Parameters
    ----------
    constants : ConstantsFile, str, Path or open file
        The mechanisms.
    site : SiteFile, str, Path or open file
        The site: hazard (NTC 2018 or EC8), FC, q, the building.

    Returns
    -------
    CheckDocument
        The document ``rockmech check --json`` prints (``to_dict()``): per mechanism
        (``find(id)``) ``passes``, ``passes_SLC``, ``Z`` [m], the governing ``linear`` and
        ``nonlinear`` checks and their ``linear_ratio``, ``nonlinear_ratio`` [-];
        ``governing``.
    """
    return _assess.check_document(_constants(constants), _site(site))


def assess(
    constants: Constants,
    site: Site,
    records: Sequence[Record] = (),
    *,
    multiples: Sequence[float] = (0.5, 1.0, 1.5, 2.0),
) -> AssessDocument:
    """Code checks beside rocking dynamics on records scaled to the site spectrum.

    As ``rockmech assess --json`` (the HTML page: ``rockmech assess -o report.html``).

    Parameters
    ----------
    constants : ConstantsFile, str, Path or open file
        The mechanisms.
    site : SiteFile, str, Path or open file
        The site.
    records : sequence of GroundMotion, str or Path
        Records for the dynamic verdict (none: the checks and envelope margins only).
    multiples : sequence of float
        Multiples of the design scale factor to run [-] (1 is the design level).

    Returns
    -------
    AssessDocument
        The document ``rockmech assess --json`` prints: the checks (as ``check``), each
        mechanism's ``dynamics`` and ``envelope``, and per mechanism id
        ``survives_design`` and ``first_overturning_multiple`` [-].
    """
    motions: list[Any] = list(_records(records))
    return _assess.assessment_document(
        _constants(constants),
        _site(site),
        motions,
        multiples=_assess.check_multiples(_numbers(multiples, "multiples")),
    )


def retrofit(
    constants: Constants,
    site: Site,
    spec: Union[RetrofitSpec, Source],
    records: Optional[Sequence[Record]] = None,
) -> RetrofitDoc:
    """Find the least tie force that makes each failing mechanism pass the 2019 code checks.

    Parameters
    ----------
    constants : ConstantsFile, str, Path or open file
        The mechanisms (``virtual_work`` and geometry per side: ``rockmech constants``).
    site : SiteFile, str, Path or open file
        The site: hazard (SLV, and SLC where given), FC, q.
    spec : RetrofitSpec, str, Path or open file
        The retrofit spec: steel grade and bars on offer, the anchorage resistance with its
        source, candidate tie heights per mechanism [m], the records (relative to its folder
        when it is a file).
    records : sequence of GroundMotion, str or Path, optional
        Records (files: formats detected) instead of the spec's ``records``: each tied
        mechanism must survive every one at its design scale, by the exact solver.

    Returns
    -------
    RetrofitDoc
        Per mechanism: ``status``, the checks ``before``, per candidate height the least tie
        force ``T_star_N`` [N] and its ``governing`` criterion, ``e_star``, the ``bar``, the
        ``anchorage`` check, the steel mass [kg] and the checks ``after`` (docs/theory.md
        §11.12).
    """
    spec_dir = None
    if isinstance(spec, RetrofitSpec):
        rspec = spec
    elif is_file_object(spec):  # an open file: its records are read from the current folder
        rspec = read_retrofit_spec(spec)
    else:
        spec_path = as_path(spec, "spec", "a RetrofitSpec or " + SOURCE_TYPES)
        rspec, spec_dir = read_retrofit_spec(spec_path), spec_path.parent
    if records is not None and len(records) > 0:
        motions = _records(records)
    else:
        motions = read_retrofit_records(rspec, spec_dir)
    return retrofit_doc(_constants(constants), _site(site), rspec, motions)


def search(
    scene: Union[BaseScene, PathLike],
    spec: Union[SearchSpec, dict[str, Any], Source],
    *,
    units: Optional[str] = None,
    site: Optional[Site] = None,
    records: Optional[Sequence[Record]] = None,
    spec_dir: Optional[PathLike] = None,
    exact: bool = False,
    limits: bool = True,
) -> SearchRun:
    """Find, build and rank a façade's rocking mechanisms (as ``rockmech search``).

    Needs the ``geometry`` extra. The walls of the scene become candidate mechanisms,
    refined on their static multiplier λ0 [-], built, and ranked by their overturning
    acceleration over the spec's pulse band [g]; the best run the records and the code check
    the spec names (docs/search.md).

    Parameters
    ----------
    scene : scene object, str or Path
        A scene (``read_scene``), or a Rhino ``.3dm`` file or a scan mesh (``.ply``,
        ``.obj``, ``.stl``, ``.off``; give ``units``) to read.
    spec : SearchSpec, dict, str, Path or open file
        The search spec: a file (JSON; its ``ranking.site`` and ``ranking.records`` are
        taken from its folder), a ``SearchSpec`` (``read_search_spec``) or a dict of its
        fields, validated as a file is.
    units : {"mm", "cm", "m", "in", "ft"}, optional
        Length unit of a scan mesh file (a ``.3dm`` states its own).
    site : SiteFile, str, Path or open file, optional
        The site for the code check, instead of the spec's ``ranking.site``.
    records : sequence of GroundMotion, str or Path, optional
        The records, instead of the spec's ``ranking.records`` (None: the spec's; an empty
        list: none).
    spec_dir : str or Path, optional
        The folder the spec's ``ranking.site`` and ``ranking.records`` are relative to
        (default: the spec file's folder; none for a spec given as an object).
    exact : bool
        Envelopes by the exact integrator instead of the fast mode (the overturning
        library, labelled in ``rankings.envelope_method``).
    limits : bool
        Apply the work limits of the command line (a search past them is refused before it
        runs; ``InputError`` on ``work_limit``).

    Returns
    -------
    SearchRun
        ``doc``, the typed ``SearchDocument`` (its ``to_dict()`` is ``search.json``):
        ``candidates`` (``SearchCandidate``, with ``lam0`` [-]; ``doc.find(id)``),
        ``rankings.static`` and ``.dynamic``, ``ranked`` (best first), ``records``,
        ``code_check``, ``timings`` [s]; ``constants`` of the mechanisms built
        (``ConstantsFile``), ``spec_file``; ``write_search`` writes them.
    """
    # The search needs the geometry extra (cad_maths, rhino3dm, trimesh): loaded when one
    # runs, so that the other analyses load without it.
    from cad_maths.scene_base import BaseScene

    # The scene reader, from the same extra.
    from cad_maths.scenes import read_scene

    # The search spec's model, with the search.
    from shared_schema.search import SearchSpec

    # The search's workflow (its figure, the 3dm writer).
    from solver_service.workflows import search as _search

    if isinstance(scene, BaseScene):
        if units is not None:
            raise InputError(
                "applies to a scene file; the scene given is already read (read_scene(path, "
                "units=...))",
                "units",
            )
        scene_obj, scene_name = scene, "scene"
    else:
        expected = "a scene (rockmech.read_scene) or " + PATH_TYPES
        scene_path = readable_file(scene, "scene", expected)
        scene_obj, scene_name = read_scene(scene_path, units=units), scene_path.name
    if isinstance(spec, (SearchSpec, dict)):
        spec_obj: Union[SearchSpec, dict[str, Any]] = spec
        spec_name, folder = "search spec", spec_dir
    elif is_file_object(spec):  # an open file: its paths are taken from spec_dir
        label = getattr(spec, "name", None)
        spec_name = os.path.basename(label) if isinstance(label, str) and label else "search spec"
        spec_obj, folder = _search.read_search_spec(spec), spec_dir
    else:
        expected = "a SearchSpec, a dict of its fields or " + SOURCE_TYPES
        spec_path = as_path(spec, "spec", expected)
        spec_obj, spec_name = _search.read_search_spec(spec_path), spec_path.name
        folder = spec_path.parent if spec_dir is None else spec_dir
    return _search.search_run(
        scene_obj,
        spec_obj,
        scene_name=scene_name,
        spec_name=spec_name,
        spec_dir=folder,
        site=None if site is None else _site(site),
        motions=None if records is None else _records(records),
        exact=exact,
        max_evaluations=_search.MAX_EVALUATIONS if limits else None,
        max_lp_blocks=_search.MAX_LP_BLOCKS if limits else None,
    )
