"""The analyses a script runs, one function each, as the ``rockmech`` command runs them.

Every function calls the workflow the command line and the REST service call, so a script,
the command line and the service give the same numbers; each returns a typed result
(``rockmech.results``) that keeps the command's whole JSON document in ``doc``. Inputs may
be given as objects (``ConstantsFile``, ``GroundMotion``, ``SiteFile``) or as file paths,
each a ``str`` or an ``os.PathLike`` (``pathlib.Path``); a missing file, a folder or an
argument of another type is an ``InputError`` naming the argument (and the path).

SI units, except where a name says otherwise (``a_p_g`` in g).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Optional, Union

from shared_schema.constants import ConstantsFile
from shared_schema.documents.assess import AssessDocument
from shared_schema.documents.check import CheckDocument
from shared_schema.documents.envelope import EnvelopeDocument
from shared_schema.documents.history import HistoryDocument
from shared_schema.errors import InputError
from shared_schema.paths import PATH_TYPES, PathLike, as_path, is_path
from shared_schema.retrofit import RetrofitDoc, RetrofitSpec, read_retrofit_spec
from shared_schema.site import SiteFile
from solver_service.core.exact import simulate
from solver_service.core.excitation import Pulse
from solver_service.core.model import RockingModel
from solver_service.core.records import GroundMotion
from solver_service.core.result import RockingResult
from solver_service.workflows import assess as _assess
from solver_service.workflows import inputs as _inputs
from solver_service.workflows import tables as _tables
from solver_service.workflows.adapter import models_from_file
from solver_service.workflows.documents import envelope_doc, frequency_grid, history_doc
from solver_service.workflows.ida import run_ida
from solver_service.workflows.retrofit import retrofit_doc
from solver_service.workflows.scaling import Building
from solver_service.workflows.units import stamp

from .results import IDAResult

__all__ = [
    "assess",
    "check",
    "constants_from_scene",
    "constants_from_table",
    "envelope",
    "history",
    "ida",
    "load_models",
    "pulse",
    "read_constants",
    "read_record",
    "read_site",
    "retrofit",
]

#: Constants given as an object or as a file (JSON, or a ``.csv``/``.xlsx`` table).
Constants = Union[ConstantsFile, PathLike]
#: A record given as an object or as a file (format detected; a two-column file in g).
Record = Union[GroundMotion, PathLike]


def read_constants(path: PathLike) -> ConstantsFile:
    """Read and validate a kinematic-constants file (JSON) or a constants table.

    Parameters
    ----------
    path : str or Path
        A ``.json`` constants file, or a ``.csv``/``.xlsx`` table with one mechanism per row
        (``.xlsx`` needs the ``tables`` extra).

    Returns
    -------
    ConstantsFile
        Every mechanism with its constants per side (``mech.positive.p_eq`` [rad/s],
        ``.lam`` [-], ``.phi_ov`` [rad]).
    """
    return _inputs.read_constants(as_path(path, "constants"))


def constants_from_table(path: PathLike) -> ConstantsFile:
    """Read a constants table (``.csv``, or ``.xlsx`` with the ``tables`` extra).

    Parameters
    ----------
    path : str or Path
        One mechanism per row: ``id``, ``rocking``, ``p_eq`` [rad/s], ``lam`` [-],
        ``eta`` [-], optional ``phi_ov`` [rad], ``f_n`` [Hz], ``h_e`` [m], ``h`` [m], ...

    Returns
    -------
    ConstantsFile
    """
    return _tables.constants_from_table(as_path(path, "table"))


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
    return _inputs.constants_from_files(as_path(scene, "scene"), as_path(spec, "spec"), units)


def _constants(constants: Constants) -> ConstantsFile:
    if isinstance(constants, ConstantsFile):
        return constants
    return read_constants(as_path(constants, "constants", "a ConstantsFile or " + PATH_TYPES))


def load_models(constants: Constants) -> list[RockingModel]:
    """Return the solver's models of every mechanism of a constants file.

    Parameters
    ----------
    constants : ConstantsFile, str or Path
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


def read_site(path: PathLike) -> SiteFile:
    """Read and validate a site file (NTC 2018 or EC8 hazard, FC, q, the building).

    Parameters
    ----------
    path : str or Path
        The site JSON file.

    Returns
    -------
    SiteFile
    """
    return _assess.read_site(as_path(path, "site"))


def _site(site: Union[SiteFile, PathLike]) -> SiteFile:
    if isinstance(site, SiteFile):
        return site
    return read_site(as_path(site, "site", "a SiteFile or " + PATH_TYPES))


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
        The mechanism (``RockingModel.symmetric`` or one of ``load_models``); needs ``eta``.
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
    constants : ConstantsFile, str or Path
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
        [float(s) for s in scales],
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
    constants : ConstantsFile, str or Path
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
    im: str = "scale",
    sf: str = "none",
    building_height: Optional[float] = None,
    criterion: Optional[str] = None,
    scheduler: Optional[str] = None,
    jobs: Optional[int] = None,
) -> IDAResult:
    """Incremental dynamic analysis: overturned fraction per level and a fragility fit.

    As ``rockmech ida``.

    Parameters
    ----------
    constants : ConstantsFile, str or Path
        The mechanisms (each needs ``eta``).
    records : sequence of GroundMotion, str or Path
        The records, at least one.
    levels : sequence of float
        Intensity levels, each > 0: scale factors [-] (``im="scale"``) or PGAs [g]
        (``im="pga"``).
    im : {"scale", "pga"}
        Intensity measure.
    sf, building_height, criterion
        As ``history``.
    scheduler : str, optional
        A dask.distributed scheduler's address (``tcp://host:8786``; the ``dask`` extra).
    jobs : int, optional
        Threads of a local run (default: every core this process may use).

    Returns
    -------
    IDAResult
        ``levels``, ``fraction`` overturned per mechanism [-], ``fragility`` (median in the
        measure's units, ``beta`` [-]).
    """
    doc = run_ida(
        _constants(constants),
        _records(records),
        [float(v) for v in levels],
        im=im,
        sf=sf,
        building=Building(building_height),
        criterion=criterion,
        scheduler=scheduler,
        jobs=jobs,
    )
    return IDAResult.from_doc(stamp(doc, "ida"))


def check(constants: Constants, site: Union[SiteFile, PathLike]) -> CheckDocument:
    """NTC 2018 / Circolare 2019 §C8.7.1 kinematic checks of every mechanism on a site.

    As ``rockmech check --json``; mechanisms need ``virtual_work`` per side.

    Parameters
    ----------
    constants : ConstantsFile, str or Path
        The mechanisms.
    site : SiteFile, str or Path
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
    site: Union[SiteFile, PathLike],
    records: Sequence[Record] = (),
    *,
    multiples: Sequence[float] = (0.5, 1.0, 1.5, 2.0),
) -> AssessDocument:
    """Code checks beside rocking dynamics on records scaled to the site spectrum.

    As ``rockmech assess --json`` (the HTML page: ``rockmech assess -o report.html``).

    Parameters
    ----------
    constants : ConstantsFile, str or Path
        The mechanisms.
    site : SiteFile, str or Path
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
        multiples=_assess.check_multiples(list(multiples)),
    )


def retrofit(
    constants: Constants,
    site: Union[SiteFile, PathLike],
    spec: Union[RetrofitSpec, PathLike],
) -> RetrofitDoc:
    """Find the least tie force that makes each failing mechanism pass the 2019 code checks.

    Parameters
    ----------
    constants : ConstantsFile, str or Path
        The mechanisms (``virtual_work`` and geometry per side: ``rockmech constants``).
    site : SiteFile, str or Path
        The site: hazard (SLV, and SLC where given), FC, q.
    spec : RetrofitSpec, str or Path
        The retrofit spec: steel grade and bars on offer, the anchorage resistance with its
        source, candidate tie heights per mechanism [m].

    Returns
    -------
    RetrofitDoc
        Per mechanism: ``status``, the checks ``before``, per candidate height the least tie
        force ``T_star_N`` [N] and its ``governing`` criterion, ``e_star``, the ``bar``, the
        ``anchorage`` check, the steel mass [kg] and the checks ``after`` (docs/theory.md
        §11.12).
    """
    rspec = (
        spec
        if isinstance(spec, RetrofitSpec)
        else read_retrofit_spec(as_path(spec, "spec", "a RetrofitSpec or " + PATH_TYPES))
    )
    return retrofit_doc(_constants(constants), _site(site), rspec)
