"""Multipart forms of the service: which files and text fields each endpoint takes.

The text fields are validated by the form models of ``shared_schema.api`` (text converted
to numbers, NaN and unknown fields refused); the files are passed to the compute process as
bytes and read there, under their sanitised names, exactly as ``rockmech`` reads files.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Optional

from fastapi import Request
from pydantic import BaseModel, ValidationError
from starlette.datastructures import FormData, UploadFile

from cad_maths.archive_3dm import check_3dm
from shared_schema.api import (
    ConstantsForm,
    HistoryForm,
    ReportForm,
    RetrofitForm,
    SearchForm,
    SpectrumForm,
)
from shared_schema.errors import InputError

from .problems import Problem, validation_message
from .uploads import safe_filename

__all__ = [
    "FORMS",
    "MAX_FORM_FIELDS",
    "MAX_FORM_FILES",
    "FormSpec",
    "form_fields",
    "multipart_schema",
    "parse_form",
    "read_form",
    "read_upload",
]

#: Most files and fields a multipart request may carry (a retrofit from a scene: the scene,
#: the search spec, the site, the retrofit spec and a record).
MAX_FORM_FILES = 5
MAX_FORM_FIELDS = 200


@dataclass(frozen=True)
class FormSpec:
    """One endpoint's multipart form.

    Attributes
    ----------
    model : type of BaseModel
        Validates the text fields.
    files : dict
        File parts: name -> (required, description).
    """

    model: type[BaseModel]
    files: dict[str, tuple[bool, str]]

    @property
    def constants(self) -> bool:
        """True when the form takes a constants file."""
        return "constants" in self.files

    @property
    def record_required(self) -> bool:
        """True when the record file is required."""
        return self.files.get("record", (False, ""))[0]

    @property
    def lists(self) -> set[str]:
        """Fields that may repeat (arrays)."""
        props = self.model.model_json_schema()["properties"]
        return {k for k, v in props.items() if _is_array(v)}


def _is_array(prop: dict[str, Any]) -> bool:
    if prop.get("type") == "array":
        return True
    return any(p.get("type") == "array" for p in prop.get("anyOf", []))


_CONSTANTS = (True, "Kinematic-constants JSON file.")
_RECORD = "Record file: PEER AT2, two columns (t, a), one column (with dt) or CSV."

#: The forms, by endpoint.
FORMS = {
    "history": FormSpec(HistoryForm, {"constants": _CONSTANTS, "record": (True, _RECORD)}),
    "spectrum": FormSpec(SpectrumForm, {"record": (True, _RECORD)}),
    "report": FormSpec(ReportForm, {"constants": _CONSTANTS, "record": (False, _RECORD)}),
    "constants": FormSpec(
        ConstantsForm,
        {"scene": (True, "Rhino .3dm file."), "spec": (True, "Mechanism spec (JSON).")},
    ),
    "search": FormSpec(
        SearchForm,
        {
            "scene": (True, "Rhino .3dm file, or a scan mesh (.ply, .obj, .stl, .off) with units."),
            "spec": (True, "Search spec (JSON): walls, levels, junctions, families, ranking."),
            "site": (False, "Site file (SITE.json) for the code check of the top mechanisms."),
            "record": (False, _RECORD),
        },
    ),
    "retrofit": FormSpec(
        RetrofitForm,
        {
            "scene": (True, "Rhino .3dm file, or a scan mesh (.ply, .obj, .stl, .off) with units."),
            "search_spec": (
                True,
                "Search spec (JSON), as rockmech retrofit --search-spec: walls, levels, "
                "junctions, tie-bars; its ranking's site and records are not read.",
            ),
            "site": (True, "Site file (SITE.json): hazard, FC, q, building."),
            "spec": (
                True,
                "Retrofit spec (JSON): steel, anchorage, candidate tie heights per mechanism "
                "id of the first search.",
            ),
            "record": (False, _RECORD + " Each tied mechanism must survive it."),
        },
    ),
}


def form_fields(form: FormData, spec: FormSpec) -> dict[str, Any]:
    """Collect the text fields of ``form`` (files excluded) for ``spec.model``.

    Raises
    ------
    ValueError
        A text field holds a file, or a single-valued field is repeated.
    """
    lists = spec.lists
    out: dict[str, Any] = {}
    for key in dict.fromkeys(form.keys()):
        if key in spec.files:
            continue
        values = form.getlist(key)
        if any(isinstance(v, UploadFile) for v in values):
            raise ValueError(f"{key}: expected a text field, got a file")
        if key in lists:
            out[key] = list(values)
        elif len(values) > 1:
            raise ValueError(f"{key}: give one value, got {len(values)}")
        else:
            out[key] = values[0]
    return out


def _not_null(prop: dict[str, Any]) -> dict[str, Any]:
    """Drop null from a form field schema (anyOf, enum, default): form text is never null."""
    out = dict(prop)
    if out.get("default", 0) is None:
        del out["default"]
    options = [p for p in out.pop("anyOf", []) if p.get("type") != "null"]
    if len(options) == 1:
        out.update(options[0])
    elif options:
        out["anyOf"] = options
    if "enum" in out:
        out["enum"] = [v for v in out["enum"] if v is not None]
    return out


def multipart_schema(spec: FormSpec) -> dict[str, Any]:
    """Return the OpenAPI schema of a multipart form (text fields and file parts)."""
    schema = spec.model.model_json_schema()
    schema.pop("title", None)
    props = {k: _not_null(v) for k, v in schema.get("properties", {}).items()}
    required = list(schema.get("required", []))
    for name, (needed, text) in spec.files.items():
        props[name] = {"type": "string", "format": "binary", "description": text}
        if needed:
            required.append(name)
    schema["properties"] = props
    schema["required"] = required
    schema["additionalProperties"] = False
    return schema


async def read_form(request: Request) -> FormData:
    """Parse a multipart body (at most ``MAX_FORM_FILES`` files, ``MAX_FORM_FIELDS`` fields)."""
    return await request.form(max_files=MAX_FORM_FILES, max_fields=MAX_FORM_FIELDS)


async def read_upload(form: FormData, name: str, required: bool) -> Optional[tuple[bytes, str]]:
    """Return an uploaded part's bytes and file name (a text part is accepted as a file)."""
    items = form.getlist(name)
    if not items:
        if required:
            raise Problem(422, "InputError", "missing; upload it as a file part", name)
        return None
    if len(items) > 1:
        raise Problem(422, "InputError", "give one file", name)
    item = items[0]
    if isinstance(item, UploadFile):
        return await item.read(), item.filename or ""
    return item.encode("utf-8"), ""


def parse_form(form: FormData, spec: FormSpec) -> dict[str, Any]:
    """Validate the text fields of ``form`` with ``spec.model``; return them as data."""
    try:
        values = form_fields(form, spec)
        return spec.model.model_validate(values).model_dump()
    except ValidationError as exc:
        message, field = validation_message(exc.errors(include_url=False), None)
        raise Problem(422, "InputError", message, field) from None
    except ValueError as exc:
        raise Problem(422, "InputError", str(exc)) from None


def check_scene_upload(data: bytes, filename: Optional[str]) -> None:
    """Check an uploaded ``.3dm`` scene's layout before a compute process reads it.

    ``cad_maths.archive_3dm.check_3dm`` (a cheap walk of the archive's chunks); a broken file
    is a 422 naming the field. Scan meshes are read by their own checked readers.
    """
    name = safe_filename(filename, "scene.3dm")
    try:
        if name.lower().endswith(".3dm"):
            check_3dm(data, name)
    except InputError as exc:
        raise Problem(422, "InputError", str(exc), exc.field) from None
