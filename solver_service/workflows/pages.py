"""The HTML pages' analyses: what ``rockmech report`` and ``rockmech assess -o`` compute.

``build_report`` runs the envelopes, the time histories, the runs drawn again with their time
series and the record's spectrum, and ``assess_report`` the assessment, the site spectrum and
the time histories at the design scale; ``solver_service.report`` then renders them and runs
no analysis of its own (``report.html.render_report``, ``report.assess.render_assessment``).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any, Optional, Union

import numpy as np

from shared_schema.constants import ConstantsFile
from shared_schema.documents.assess import AssessDocument
from shared_schema.documents.check import CheckMechanism
from shared_schema.documents.history import HistoryDocument
from shared_schema.errors import InputError, RockmechError
from shared_schema.paths import PATH_TYPES, PathLike, as_path
from shared_schema.retrofit import RetrofitDoc, RetrofitSpec
from shared_schema.rules import check_positive
from shared_schema.site import SiteFile

from ..core.exact import simulate
from ..core.model import G
from ..core.pulses import extract_pulses
from ..core.records import GroundMotion
from ..core.spectra import response_spectrum
from ..report.assess import HistoryRun, check_template, render_assessment, sig
from ..report.html import SPECTRUM_PERIODS, ReportContent, render_report
from ..report.retrofit import check_retrofit_matches
from .adapter import to_rocking_model
from .assess import (
    assessment_doc,
    check_doc_with_records,
    site_spectrum,
    typed_assessment,
    typed_check,
)
from .documents import envelope_doc, history_doc
from .scaling import Building, dense_runs, mechanism_scale_factor

__all__ = ["assess_report", "assessment_histories", "build_report", "check_history_options"]

#: What a run or a figure's data may fail with: its figure then says why instead.
FIGURE_ERRORS = (ValueError, ArithmeticError, RockmechError)


def check_history_options(
    scales: Sequence[float], history: Optional[dict[str, Any]], motion: Optional[Any]
) -> None:
    """Refuse history options that are invalid, or that have nothing to act on.

    The scale factors must be > 0 with or without a record; without a record there are no
    time histories, so scales, ``sf``, the building, ``criterion`` and ``at_height`` given
    then would be silently ignored and are refused instead (issue #14).

    Raises
    ------
    InputError
        A scale not finite and > 0 (field ``scales[j]``), or an option given without a record
        (field: its name).
    """
    for j, value in enumerate(scales):
        check_positive(value, f"scales[{j}]")
    if motion is not None:
        return
    opts = dict(history or {})
    given = {
        "scales": [float(v) for v in scales] != [1.0],
        "sf": opts.get("sf", "none") != "none",
        "building": opts.get("building", Building()) != Building(),
        "criterion": opts.get("criterion") is not None,
        "at_height": opts.get("at_height") is not None,
    }
    named = [name for name, is_given in given.items() if is_given]
    if named:
        raise InputError(
            "acts on the time histories of a record, and no record is given; give a record "
            f"or leave out {' and '.join(named)}",
            named[0],
        )


def _report_inputs(cf: Any, motion: Any) -> tuple[ConstantsFile, Any]:
    """Return the constants and the record of a report, read where given as paths."""
    # read here, not at import: the readers pull in the scene readers (cad_maths)
    from .inputs import read_constants, read_record

    if not isinstance(cf, ConstantsFile):
        cf = read_constants(as_path(cf, "constants", "a ConstantsFile or " + PATH_TYPES))
    if motion is not None and not isinstance(motion, GroundMotion):
        motion = read_record(as_path(motion, "motion", "a GroundMotion or " + PATH_TYPES))
    return cf, motion


def _record_content(cf: ConstantsFile, motion: GroundMotion) -> dict[str, Any]:
    """Return the record's 5 % spectrum, its largest pulse and S_a at each structure's period."""
    periods = np.geomspace(*SPECTRUM_PERIODS[:2], int(SPECTRUM_PERIODS[2]))
    out: dict[str, Any] = {}
    try:
        out["spectrum"] = response_spectrum(motion.accel.acc, motion.dt, periods, 0.05)
        out["pulses"] = extract_pulses(motion.accel, n=1)
    except FIGURE_ERRORS as exc:
        out = {"record_error": exc}
    spectral = []
    for m in cf.mechanisms:
        if m.amplification is None:
            continue
        t_n = 1.0 / m.amplification.f_n
        sa = float(response_spectrum(motion.accel.acc, motion.dt, [t_n]).psa[0]) / G
        spectral.append((m.id, t_n, sa))
    out["spectral"] = spectral
    return out


def _history_runs(
    cf: ConstantsFile, motion: GroundMotion, hist: HistoryDocument, top: float
) -> dict[str, Any]:
    """Return the runs at the largest scale with their time series, or why they cannot be made."""
    try:
        # the runs are made again with their time series: a run can fail here alone
        runs = [
            (f"{mech_id} ×{scale:.3g}", res)
            for mech_id, scale, res in dense_runs(cf, motion, hist.to_dict(), top)
        ]
    except FIGURE_ERRORS as exc:
        return {"runs_error": str(exc)}
    return {"runs": runs}


def build_report(
    constants: Union[ConstantsFile, PathLike],
    f_p: Any,
    *,
    motion: Union[GroundMotion, PathLike, None] = None,
    scales: Sequence[float] = (1.0,),
    history: Optional[dict[str, Any]] = None,
    method: str = "exact",
    title: str = "",
    sources: Sequence[dict[str, Any]] = (),
    request: Optional[dict[str, Any]] = None,
    library: Optional[Any] = None,
) -> str:
    """Return the HTML report of a constants file and, optionally, a record.

    Parameters
    ----------
    constants : ConstantsFile, str or os.PathLike
        The mechanisms, or a constants file or table to read (``read_constants``).
    f_p : (n,) float
        Pulse frequencies of the envelopes [Hz].
    motion : GroundMotion, str or os.PathLike, optional
        A record, or a record file to read (``read_record``'s defaults): adds its spectrum
        and the time histories.
    scales : sequence of float
        Scale factors on the record [-].
    history : dict, optional
        Options of the time histories, passed to ``history_doc`` (``sf``, ``building``,
        ``criterion``, ``at_height``).
    method : {"exact", "library"}
        How the envelopes are computed (``envelope_doc``; exact by default).
    title : str
        Report title.
    sources : sequence of dict
        Inputs (``report.html.input_source``) for the provenance table.
    request : dict, optional
        Analysis options, shown as given.
    library : OverturningLibrary, optional
        A loaded library for ``method="library"`` (else loaded here).

    Returns
    -------
    str
        The page (``report.html.render_report``).

    Raises
    ------
    InputError
        Invalid history options, or options given without a record
        (``check_history_options``); a file that cannot be read, or a ``constants`` or
        ``motion`` of another type (naming it).
    """
    cf, record = _report_inputs(constants, motion)
    check_history_options(scales, history, record)
    env_doc, envelopes = envelope_doc(
        cf, np.asarray(f_p, dtype=float), method=method, library=library
    )
    extra: dict[str, Any] = {}
    if record is not None:
        hist = history_doc(cf, record, list(scales), **(history or {}))
        top = max(scales)
        extra = {"hist": hist, "top": top, **_record_content(cf, record)}
        extra.update(_history_runs(cf, record, hist, top))
    content = ReportContent(cf, env_doc, envelopes, record, **extra)
    return render_report(content, title=title, sources=sources, request=request)


def _mechanism_histories(
    mech: Any, row: CheckMechanism, motions: Sequence[GroundMotion]
) -> list[HistoryRun]:
    """One mechanism's time histories at each record's design scale (× Eq. 28 up the building)."""
    try:
        model = to_rocking_model(mech)
    except RockmechError as exc:
        return [HistoryRun("time histories", note=f"not run: {exc}")]
    out: list[HistoryRun] = []
    for k, (motion, dyn) in enumerate(zip(motions, row.dynamics or [])):
        if dyn.scale_factor is None or dyn.scale_factor.value is None:
            continue
        design = float(dyn.scale_factor.value)
        caption = f"{mech.id} on {motion.name} at the design scale {sig(design)}"
        try:
            height = mechanism_scale_factor(mech, motion, "eq28")
        except FIGURE_ERRORS as exc:
            out.append(HistoryRun(caption, note=f"not run: {exc}"))
            continue
        up = 1.0 if height is None else float(height["value"])
        caption += (
            f" × {sig(up)} up the structure (Eq. 28)" if height is not None else ""
        ) + "; time axis cropped to the motion"
        run = HistoryRun(caption, mech.id, motion, design, file=f"{mech.id}_history_{k}.png")
        try:
            result = simulate(model, motion.accel, scale=design * up, dense=True)
        except FIGURE_ERRORS as exc:
            out.append(HistoryRun(caption, note=f"not drawn: {exc}"))
            continue
        out.append(HistoryRun(run.caption, run.label, motion, design, result, file=run.file))
    return out


def assessment_histories(
    cf: ConstantsFile, doc: AssessDocument, motions: Sequence[GroundMotion]
) -> dict[str, list[HistoryRun]]:
    """Per mechanism of an assessment document, its time histories at the design scale.

    Parameters
    ----------
    cf : ConstantsFile
        The mechanisms of ``doc``.
    doc : AssessDocument
        ``workflows.assess.assessment_document(cf, site, motions, ...)``.
    motions : sequence of GroundMotion
        Its records, in its order.

    Returns
    -------
    dict of str to list of HistoryRun
        Each run with its time series, or the note on why it was not run or drawn.
    """
    by_id = {m.id: m for m in cf.mechanisms}
    return {row.id: _mechanism_histories(by_id[row.id], row, motions) for row in doc.mechanisms}


def assessment_retrofit(
    cf: ConstantsFile,
    site: SiteFile,
    source: Union[RetrofitSpec, RetrofitDoc],
    motions: Sequence[Any] = (),
) -> RetrofitDoc:
    """Return the retrofit a report shows: computed from a spec, or a document checked.

    Parameters
    ----------
    cf, site
        The assessment's constants and site.
    source : RetrofitSpec or RetrofitDoc
        A retrofit spec (the retrofit is run on ``cf``, ``site`` and the assessment's
        records, as ``rockmech retrofit --record`` runs it) or a ``retrofit.json``, checked
        against the code checks of ``cf`` on ``site`` (``report.retrofit.check_retrofit_matches``),
        with the records' demand where the document was made with records, as it then ran
        them.
    motions : sequence of GroundMotion
        The assessment's records.

    Raises
    ------
    InputError
        The spec's errors, their field under ``retrofit.`` (``retrofit.mechanisms.F9``);
        a document made from other inputs (``retrofit``).
    """
    if isinstance(source, RetrofitDoc):
        # The code checks as the retrofit ran them: with the records' demand if it had any.
        doc, _ = check_doc_with_records(cf, site, motions if source.records else ())
        check_retrofit_matches(source, typed_check(doc).mechanisms)
        return source
    # The retrofit (its bisections on the code checks) is loaded only when a spec is given.
    from .retrofit import retrofit_doc

    try:
        return retrofit_doc(cf, site, source, motions)
    except InputError as exc:
        head = (exc.field or "").split(".", 1)[0]
        if head in ("mechanisms", "steel", "anchorage"):
            raise InputError(exc.reason, f"retrofit.{exc.field}") from None
        raise


def assess_report(
    cf: ConstantsFile,
    site: SiteFile,
    motions: Sequence[GroundMotion],
    *,
    multiples: Sequence[float] = (0.5, 1.0, 1.5, 2.0),
    sources: Sequence[dict[str, Any]] = (),
    options: Optional[dict[str, Any]] = None,
    template_dir: Optional[Path] = None,
    retrofit: Union[RetrofitSpec, RetrofitDoc, None] = None,
) -> tuple[dict[str, Any], str]:
    """Return the assessment document and its HTML page (for ``rockmech assess`` and REST).

    Parameters
    ----------
    cf, site, motions, multiples
        As ``workflows.assess.assessment_doc``.
    sources, options, template_dir
        As ``report.assess.render_assessment``.
    retrofit : RetrofitSpec or RetrofitDoc, optional
        A retrofit spec (the retrofit is run on ``cf`` and ``site``) or a ``retrofit.json``
        made from them (checked: ``assessment_retrofit``): the document holds it under
        ``retrofit`` and page one shows its table.

    Returns
    -------
    (dict, str)
        The JSON-ready document and the HTML page.
    """
    check_template(template_dir)  # a user template's syntax error before the analysis runs
    doc = assessment_doc(cf, site, motions, multiples=multiples)
    if retrofit is not None:
        made = assessment_retrofit(cf, site, retrofit, motions)
        doc["retrofit"] = made.model_dump(mode="json")
    typed = typed_assessment(doc)  # the page reads the typed document
    text = render_assessment(
        typed,
        cf,
        site,
        site_spectrum(site),
        assessment_histories(cf, typed, motions),
        sources=sources,
        options=options,
        template_dir=template_dir,
    )
    return doc, text
