"""Reading what users give: records (format detected), constants files, scenes with specs."""

from __future__ import annotations

import csv
import io
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Optional, Union

from cad_maths.mechanisms.build import (
    MechanismFailure,
    constants_and_failures,
    constants_from_spec,
    failures_error,
)
from cad_maths.scenes import SCENE_FORMATS, read_scene
from shared_schema import io as constants_io
from shared_schema.api import time_domain_problem
from shared_schema.constants import ConstantsFile, json_document
from shared_schema.errors import InputError, RockmechError
from shared_schema.io import CONSTANTS_EXPECTED, parse_constants
from shared_schema.paths import (
    SOURCE_TYPES,
    PathLike,
    Source,
    as_path,
    is_file_object,
    read_source,
    readable_file,
)
from shared_schema.rules import RECORD_FORMATS, RECORD_UNITS, check_file, check_positive
from shared_schema.site import SITE_EXPECTED, SiteFile, site_from_text
from shared_schema.spec import parse_spec
from shared_schema.text import decode_text

from ..core.records import GroundMotion, detect_format
from .tables import constants_from_table, is_table

__all__ = [
    "RecordSpec",
    "constants_and_failures_from_scene_files",
    "constants_from_scene_files",
    "file_kind",
    "read_constants",
    "read_record",
    "read_record_spec",
    "read_site_file",
]

#: What a record-spec file must be, for the messages on empty or binary files.
RECORD_SPEC_EXPECTED = "a list of records (CSV with a header row 'file,format,units,...', or JSON)"
#: Columns (CSV) or keys (JSON) of a record-spec file; only ``file`` is required.
SPEC_FIELDS = ("file", "format", "units", "dt", "channel", "component")


def read_record(
    path: PathLike,
    fmt: Optional[str] = None,
    units: Optional[str] = None,
    dt: Optional[float] = None,
    channel: Union[int, str, None] = None,
    component: Optional[str] = None,
    *,
    on_warning: Optional[Callable[[str], None]] = None,
) -> GroundMotion:
    """Read a record as ``rockmech`` does: format detected, a two-column file in g by default.

    The one place every front end reads a record file: each warning of the record (an
    implausible PGA or time step naming the units read, a shifted time axis, a header that
    could not be checked) is passed to ``on_warning`` as it is read, and stays in
    ``motion.warnings`` for the documents.

    Parameters
    ----------
    path : str or os.PathLike
        The record file.
    fmt, units, dt, channel, component
        As ``GroundMotion.from_file``; ``units`` defaults to g for a two-column file (the
        t [s], a [g] convention of the bundled record); ``channel`` or ``component`` choose
        one channel of a file with several (DMG V2, GeoNet V2A).
    on_warning : callable, optional
        Called with each warning (the CLI prints ``warning: record: ...`` on stderr).
    """
    path = as_path(path, "record")
    fmt = fmt or detect_format(path)
    if units is None and fmt == "two_column":
        units = "g"
    motion = GroundMotion.from_file(
        path, format=fmt, units=units, dt=dt, channel=channel, component=component
    )
    if on_warning is not None:
        for note in motion.warnings:
            on_warning(note)
    return motion


@dataclass(frozen=True)
class RecordSpec:
    """How to read one record of a list: the file and its ``read_record`` options."""

    file: Path
    format: Optional[str] = None
    units: Optional[str] = None
    dt: Optional[float] = None
    channel: Optional[str] = None
    component: Optional[str] = None

    def read(self, on_warning: Optional[Callable[[str], None]] = None) -> GroundMotion:
        """Read the record (``read_record``; its warnings to ``on_warning``)."""
        return read_record(
            self.file,
            self.format,
            self.units,
            self.dt,
            self.channel,
            self.component,
            on_warning=on_warning,
        )


def _spec_rows(path: Path, text: str) -> list[tuple[str, dict[str, Any]]]:
    """``(row label, fields)`` of a record-spec file: JSON list of objects or CSV with header."""
    if path.suffix.lower() == ".json":
        try:
            doc = json_document(text)
        except InputError as exc:
            raise InputError(f"{path.name}: {exc.reason}", "record_spec") from None
        if not isinstance(doc, list) or not all(isinstance(r, dict) for r in doc):
            raise InputError(f"{path.name}: expected a JSON list of objects", "record_spec")
        return [(f"record_spec[{i}]", dict(r)) for i, r in enumerate(doc)]
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    rows = list(csv.reader(io.StringIO("\n".join(lines))))
    if not rows:
        raise InputError(f"{path.name} is empty", "record_spec")
    header = [h.strip().lower() for h in rows[0]]
    out = []
    for n, cells in enumerate(rows[1:], start=2):
        if len(cells) > len(header):
            raise InputError(
                f"row {n} has {len(cells)} cells, the header {len(header)}", "record_spec"
            )
        fields = {h: c.strip() for h, c in zip(header, cells) if c.strip()}
        out.append((f"record_spec row {n}", fields))
    return out


def read_record_spec(path: PathLike) -> list[RecordSpec]:
    """Read a list of records, each with its own format, units, dt, channel or component.

    Parameters
    ----------
    path : str or os.PathLike
        A CSV file with a header row naming some of ``SPEC_FIELDS`` (``file`` required;
        empty cells mean "detect" or "not given"), or a JSON list of objects with those
        keys. Relative file names are taken from the spec's folder.

    Raises
    ------
    InputError
        An unknown column or key, a row without ``file``, a ``dt`` that is not a positive
        number, or an unknown format or units; the message names the row and the column.
    """
    path = check_file(path, "record_spec")
    text = decode_text(path.read_bytes(), path.name, "record_spec", RECORD_SPEC_EXPECTED)
    rows = _spec_rows(path, text)
    if not rows:
        raise InputError(f"{path.name} lists no records", "record_spec")
    specs = []
    for label, fields in rows:
        unknown = sorted(set(fields) - set(SPEC_FIELDS))
        if unknown:
            raise InputError(
                f"{label}: unknown column {unknown[0]!r}; columns are {list(SPEC_FIELDS)}",
                "record_spec",
            )
        if not fields.get("file"):
            raise InputError(f"{label}, column 'file': missing", "record_spec")
        values: dict[str, Any] = {}
        for key in SPEC_FIELDS[1:]:
            value = fields.get(key)
            if value is None or value == "":
                continue
            if key == "dt":
                try:
                    values[key] = check_positive(float(value), "dt")
                except (TypeError, ValueError, InputError):
                    raise InputError(
                        f"{label}, column 'dt': must be a number > 0 [s], got {value!r}",
                        "record_spec",
                    ) from None
                continue
            if key == "format" and value not in RECORD_FORMATS:
                raise InputError(
                    f"{label}, column 'format': must be one of {list(RECORD_FORMATS)}, "
                    f"got {value!r}",
                    "record_spec",
                )
            if key == "units" and value not in RECORD_UNITS:
                raise InputError(
                    f"{label}, column 'units': must be one of {list(RECORD_UNITS)}, got {value!r}",
                    "record_spec",
                )
            values[key] = str(value)
        specs.append(RecordSpec(path.parent / str(fields["file"]), **values))
    return specs


#: What each kind of input file is, for a message about a file given in the wrong place.
FILE_KINDS = {
    "constants": "a kinematic-constants file",
    "site": "a site file (SITE.json)",
    "spec": "a mechanism spec",
    "scene": "a scene file",
    "record": "a ground-motion record",
}
#: Keys of a spec's mechanism that a constants file's mechanism never has.
_SPEC_KEYS = {"groups", "blocks", "axis", "hinges", "floors", "roof", "vaults", "tie_bars"}
#: Keys of a constants file's mechanism that a spec's mechanism never has.
_CONSTANTS_KEYS = {"positive", "negative", "p_eq", "lam", "phi_ov", "eta_source"}


def file_kind(path: Path) -> Optional[str]:
    """Guess which of rockmech's inputs a file is (a key of ``FILE_KINDS``), or None.

    Used only to word an error once a file failed to read as what it was given for: a scene
    by its extension, a JSON document by its top-level keys (a site file has ``hazard``; a
    spec's mechanisms have ``groups`` or ``axis``, a constants file's ``positive`` or
    ``p_eq``), a record by its format being recognised.
    """
    if path.suffix.lower().lstrip(".") in SCENE_FORMATS:
        return "scene"
    if is_table(path):
        try:
            constants_from_table(path)
        except (OSError, RockmechError):
            pass
        else:
            return "constants"
    try:
        doc = json_document(path.read_bytes().decode("utf-8-sig"))
    except (OSError, UnicodeDecodeError):
        return None
    except InputError:
        try:
            detect_format(path)
        except (OSError, RockmechError):
            return None
        return "record"
    if isinstance(doc, list):
        doc = {"mechanisms": doc}
    if not isinstance(doc, dict):
        return None
    if "hazard" in doc:
        return "site"
    if "spec_version" in doc:
        return "spec"
    mechs = doc.get("mechanisms")
    keys = set()
    for mech in mechs if isinstance(mechs, list) else []:
        keys |= set(mech) if isinstance(mech, dict) else set()
    if keys & _SPEC_KEYS and not keys & _CONSTANTS_KEYS:
        return "spec"
    if keys & _CONSTANTS_KEYS:
        return "constants"
    return None


def _wrong_file(path: Path, expected: str, where: str) -> Optional[InputError]:
    """Return the error for a file of another kind than ``expected``, or None."""
    kind = file_kind(path)
    if kind is None or kind == expected:
        return None
    if kind in ("spec", "scene") and expected == "constants":
        where = "compute the constants first: rockmech constants SCENE SPEC -o constants.json"
    if kind == "record" and expected == "constants":
        where = "the first argument is the kinematic-constants file, the records come after it"
    return InputError(
        f"{path.name}: this looks like {FILE_KINDS[kind]}, not {FILE_KINDS[expected]}; {where}",
        expected,
    )


def read_constants(path: Source, *, time_domain: bool = False) -> ConstantsFile:
    """Read and validate a kinematic-constants file, or a constants table (``.csv``, ``.xlsx``).

    Parameters
    ----------
    path : str, os.PathLike or file object
        The file; an open file is read as a JSON constants file (a table is read from its
        path: its format is the path's suffix).
    time_domain : bool
        Also hold every mechanism to the ranges of a time-domain analysis (each side's
        ``p_eq`` and ``lam``, the amplification data; ``shared_schema.api.time_domain_problem``),
        the ranges the REST service applies to envelope, history, report and assess requests.

    Raises
    ------
    InputError
        Errors name ``constants`` (a JSON file) or ``table`` with the row and column (a table,
        ``solver_service.workflows.tables``). A site file, spec or scene given instead is
        named as such (the arguments were swapped).
    """
    if is_file_object(path):
        cf = _constants_from_stream(path)
        problem = time_domain_problem(cf) if time_domain else None
        if problem is not None:
            raise InputError(f"{problem[0]}: {problem[1]}", "constants")
        return cf
    path = readable_file(path, "constants", SOURCE_TYPES)
    if is_table(path):
        return constants_from_table(path, time_domain=time_domain)
    try:
        cf = constants_io.read_constants(path)
    except InputError as exc:
        wrong = _wrong_file(
            path,
            "constants",
            "the first argument is the kinematic-constants file (check and assess take the "
            "site file second)",
        )
        raise (wrong or exc) from None
    problem = time_domain_problem(cf) if time_domain else None
    if problem is not None:
        raise InputError(f"{problem[0]}: {problem[1]}", str(path))
    return cf


def _constants_from_stream(stream: object) -> ConstantsFile:
    """Read a JSON constants file given as an open file; errors name its ``.name``."""
    raw, name = read_source(stream, "constants")
    if is_table(name):
        raise InputError(
            f"{name}: a constants table is read from its path (the suffix says its format), "
            "not from an open file; pass the path",
            "constants",
        )
    text = decode_text(raw, name, "constants", CONSTANTS_EXPECTED)
    try:
        return parse_constants(text)
    except InputError as exc:
        raise InputError(str(exc), name) from None


def read_site_file(path: Source) -> SiteFile:
    """Read and validate a site file (``shared_schema.site.read_site``); field ``site``.

    ``path`` is a path or an open file (``shared_schema.paths.read_source``). A constants
    file or another of rockmech's inputs given instead (as a path) is named as such (the
    arguments of ``check`` or ``assess`` were swapped).
    """
    raw, name = read_source(path, "site")
    text = decode_text(raw, name, "site", SITE_EXPECTED)
    try:
        return site_from_text(text, name)
    except InputError:
        if is_file_object(path):
            raise
        wrong = _wrong_file(
            Path(os.fspath(path)),  # type: ignore[arg-type]
            "site",
            "the second argument is the site file (check and assess take the constants file first)",
        )
        if wrong is not None:
            raise wrong from None
        raise


#: What a mechanism spec must be, for the messages on empty, binary or non-JSON files.
SPEC_EXPECTED = 'a mechanism spec (JSON, {"mechanisms": [...]})'


def _spec_and_scene(
    scene_path: PathLike, spec_path: PathLike, units: Optional[str]
) -> tuple[Path, Path, Any, Any]:
    """Check and read a scene and its spec: ``(scene path, spec path, spec, scene)``."""
    scene = check_file(scene_path, "scene")
    spec = check_file(spec_path, "spec")
    scene_is_json = scene.suffix.lower() == ".json"
    if spec.suffix.lower().lstrip(".") in SCENE_FORMATS:
        where = (
            "the arguments are swapped: the first is the scene (.3dm or a scan mesh), the "
            "second the spec (JSON)"
            if scene_is_json
            else "the spec is a JSON file, given after the scene"
        )
        raise InputError(f"{spec.name}: this is {FILE_KINDS['scene']}, not a spec; {where}", "spec")
    if scene_is_json and file_kind(scene) in ("spec", "constants", "site"):
        what = FILE_KINDS[str(file_kind(scene))]
        raise InputError(
            f"{scene.name}: this looks like {what}, not a scene; the first argument is the "
            "scene (.3dm or a scan mesh), the second the spec (JSON)",
            "scene",
        )
    text = decode_text(spec.read_bytes(), spec.name, "spec", SPEC_EXPECTED)
    return scene, spec, parse_spec(text, spec.name), read_scene(scene, units=units)


def constants_from_scene_files(
    scene: PathLike, spec: PathLike, units: Optional[str] = None
) -> ConstantsFile:
    """Kinematic constants of every mechanism of a spec file from the solids of a scene file.

    Parameters
    ----------
    scene : str or os.PathLike
        Rhino ``.3dm`` file (read with rhino3dm) or a scan mesh (``.ply``, ``.obj``, ``.stl``,
        ``.off``, read with trimesh; ``cad_maths.scenes.read_scene``).
    spec : str or os.PathLike
        Mechanism spec (JSON); relative paths inside it are taken from its folder.
    units : {"mm", "cm", "m", "in", "ft"}, optional
        Length unit of a scan mesh (required there; a ``.3dm`` states its own).

    Raises
    ------
    InputError
        A missing or unreadable scene or spec (field ``scene`` or ``spec``, naming the path),
        or a path that is not a ``str`` or ``os.PathLike``.
    RockmechError
        If any mechanism fails; the message lists every failed mechanism.
    """
    scene_file, spec_path, spec_file, scene_obj = _spec_and_scene(scene, spec, units)
    return constants_from_spec(
        spec_file,
        scene_obj,
        scene_name=scene_file.name,
        spec_name=spec_path.name,
        spec_dir=spec_path.parent,
    )


def constants_and_failures_from_scene_files(
    scene: PathLike, spec: PathLike, units: Optional[str] = None
) -> tuple[ConstantsFile, list[MechanismFailure]]:
    """Like ``constants_from_scene_files``, but keep the mechanisms that succeed.

    Returns
    -------
    constants : ConstantsFile
        The mechanisms that succeeded, in spec order.
    failures : list of MechanismFailure
        The mechanisms that failed, each with its error.

    Raises
    ------
    RockmechError
        If the files cannot be read, or if every mechanism fails (nothing to write).
    """
    scene_file, spec_path, spec_file, scene_obj = _spec_and_scene(scene, spec, units)
    cf, failures = constants_and_failures(
        spec_file,
        scene_obj,
        scene_name=scene_file.name,
        spec_name=spec_path.name,
        spec_dir=spec_path.parent,
    )
    if cf is None:
        raise failures_error(failures, len(spec_file.mechanisms))
    return cf, failures
