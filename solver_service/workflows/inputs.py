"""Reading what users give: records (format detected), constants files, scenes with specs."""

from __future__ import annotations

import csv
import io
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Optional, Union

from rhino_plugin.mechanisms.build import (
    MechanismFailure,
    constants_and_failures,
    constants_from_spec,
    failures_error,
)
from rhino_plugin.scenes import read_scene
from shared_schema.constants import ConstantsFile, json_document
from shared_schema.errors import InputError
from shared_schema.io import load_constants
from shared_schema.rules import RECORD_FORMATS, RECORD_UNITS, check_file, check_positive
from shared_schema.spec import parse_spec
from shared_schema.text import decode_text

from ..core.records import GroundMotion, detect_format
from .tables import constants_from_table, is_table

__all__ = [
    "RecordSpec",
    "constants_from_files",
    "constants_keep_going",
    "read_constants",
    "read_record",
    "read_record_spec",
]

#: What a record-spec file must be, for the messages on empty or binary files.
RECORD_SPEC_EXPECTED = "a list of records (CSV with a header row 'file,format,units,...', or JSON)"
#: Columns (CSV) or keys (JSON) of a record-spec file; only ``file`` is required.
SPEC_FIELDS = ("file", "format", "units", "dt", "channel", "component")


def read_record(
    path: Path,
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
    path : Path
        The record file.
    fmt, units, dt, channel, component
        As ``GroundMotion.from_file``; ``units`` defaults to g for a two-column file (the
        t [s], a [g] convention of the bundled record); ``channel`` or ``component`` choose
        one channel of a file with several (DMG V2, GeoNet V2A).
    on_warning : callable, optional
        Called with each warning (the CLI prints ``warning: record: ...`` on stderr).
    """
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


def read_record_spec(path: Path) -> list[RecordSpec]:
    """Read a list of records, each with its own format, units, dt, channel or component.

    Parameters
    ----------
    path : Path
        A CSV file with a header row naming some of ``SPEC_FIELDS`` (``file`` required;
        empty cells mean "detect" or "not given"), or a JSON list of objects with those
        keys. Relative file names are taken from the spec's folder.

    Raises
    ------
    InputError
        An unknown column or key, a row without ``file``, a ``dt`` that is not a positive
        number, or an unknown format or units; the message names the row and the column.
    """
    check_file(path, "record_spec")
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


def read_constants(path: Path) -> ConstantsFile:
    """Read and validate a kinematic-constants file, or a constants table (``.csv``, ``.xlsx``).

    Errors name ``constants`` (a JSON file) or ``table`` with the row and column (a table,
    ``solver_service.workflows.tables``).
    """
    check_file(path, "constants")
    if is_table(path):
        return constants_from_table(path)
    return load_constants(path)


#: What a mechanism spec must be, for the messages on empty, binary or non-JSON files.
SPEC_EXPECTED = 'a mechanism spec (JSON, {"mechanisms": [...]})'


def _spec_and_scene(scene: Path, spec: Path, units: Optional[str]) -> tuple[Any, Any]:
    for label, path in (("scene", scene), ("spec", spec)):
        check_file(path, label)
    text = decode_text(spec.read_bytes(), spec.name, "spec", SPEC_EXPECTED)
    return parse_spec(text, spec.name), read_scene(scene, units=units)


def constants_from_files(scene: Path, spec: Path, units: Optional[str] = None) -> ConstantsFile:
    """Kinematic constants of every mechanism of a spec file from the solids of a scene file.

    Parameters
    ----------
    scene : Path
        Rhino ``.3dm`` file (read with rhino3dm) or a scan mesh (``.ply``, ``.obj``, ``.stl``,
        ``.off``, read with trimesh; ``rhino_plugin.scenes.read_scene``).
    spec : Path
        Mechanism spec (JSON); relative paths inside it are taken from its folder.
    units : {"mm", "cm", "m", "in", "ft"}, optional
        Length unit of a scan mesh (required there; a ``.3dm`` states its own).

    Raises
    ------
    RockmechError
        If any mechanism fails; the message lists every failed mechanism.
    """
    spec_file, scene_obj = _spec_and_scene(scene, spec, units)
    return constants_from_spec(
        spec_file,
        scene_obj,
        scene_name=scene.name,
        spec_name=spec.name,
        spec_dir=spec.parent,
    )


def constants_keep_going(
    scene: Path, spec: Path, units: Optional[str] = None
) -> tuple[ConstantsFile, list[MechanismFailure]]:
    """Like ``constants_from_files``, but keep the mechanisms that succeed.

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
    spec_file, scene_obj = _spec_and_scene(scene, spec, units)
    cf, failures = constants_and_failures(
        spec_file,
        scene_obj,
        scene_name=scene.name,
        spec_name=spec.name,
        spec_dir=spec.parent,
    )
    if cf is None:
        raise failures_error(failures, len(spec_file.mechanisms))
    return cf, failures
