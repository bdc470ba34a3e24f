"""Export the JSON Schemas of the input files: constants, site, search, mechanism, retrofit.

Run ``python -m shared_schema.export`` after changing ``shared_schema.constants``,
``shared_schema.site``, ``shared_schema.search``, ``shared_schema.spec`` or
``shared_schema.retrofit``; it writes
``shared_schema/jsonschema/kinematic_constants.schema.json``,
``shared_schema/jsonschema/site.schema.json``, ``shared_schema/jsonschema/search.schema.json``,
``shared_schema/jsonschema/spec.schema.json`` (one ``oneOf`` branch per typology, from
``shared_schema.spec.TYPOLOGY_SPECS``) and ``shared_schema/jsonschema/retrofit.schema.json``.
With ``--check`` it writes nothing and exits 1 when a file on disk differs from the models (a
test does the same).
"""

import argparse
import json
import sys
from pathlib import Path
from typing import Any, Dict, List, Optional, Type

from pydantic import BaseModel

from shared_schema.constants import ConstantsFile
from shared_schema.io import write_atomic
from shared_schema.retrofit import RetrofitSpec
from shared_schema.search import SearchSpec
from shared_schema.site import SiteFile
from shared_schema.spec import SpecFile

__all__ = [
    "RETROFIT_SCHEMA_PATH",
    "SCHEMA_PATH",
    "SEARCH_SCHEMA_PATH",
    "SITE_SCHEMA_PATH",
    "SPEC_SCHEMA_PATH",
    "build_retrofit_schema",
    "build_schema",
    "build_search_schema",
    "build_site_schema",
    "build_spec_schema",
    "main",
    "render_retrofit_schema",
    "render_schema",
    "render_search_schema",
    "render_site_schema",
    "render_spec_schema",
]

#: Where the exported schema lives (shipped as package data).
SCHEMA_PATH = Path(__file__).resolve().parent / "jsonschema" / "kinematic_constants.schema.json"

#: Where the exported site-file schema lives.
SITE_SCHEMA_PATH = SCHEMA_PATH.parent / "site.schema.json"

#: Where the exported search-spec schema lives.
SEARCH_SCHEMA_PATH = SCHEMA_PATH.parent / "search.schema.json"

#: Where the exported mechanism-spec schema lives.
SPEC_SCHEMA_PATH = SCHEMA_PATH.parent / "spec.schema.json"

#: Where the exported retrofit-spec schema lives.
RETROFIT_SCHEMA_PATH = SCHEMA_PATH.parent / "retrofit.schema.json"

#: JSON Schema dialect pydantic generates.
DIALECT = "https://json-schema.org/draft/2020-12/schema"


def _schema_of(model: Type[BaseModel], title: str) -> Dict[str, Any]:
    """Return a model's validation JSON Schema in the draft pydantic writes, with its title."""
    schema = model.model_json_schema(mode="validation")
    schema["$schema"] = DIALECT
    schema["title"] = title
    return schema


def build_schema() -> Dict[str, Any]:
    """Return the JSON Schema of ``ConstantsFile`` as a dict.

    Returns
    -------
    dict
        A draft 2020-12 schema. It describes the canonical object form; the loader also
        accepts a bare list of mechanisms.
    """
    return _schema_of(ConstantsFile, "rockmech kinematic-constants file")


def render_schema() -> str:
    """Return the schema as the text stored on disk (sorted keys, indent 2, final newline)."""
    return json.dumps(build_schema(), sort_keys=True, indent=2, ensure_ascii=False) + "\n"


def build_site_schema() -> Dict[str, Any]:
    """Return the JSON Schema of ``SiteFile`` (draft 2020-12) as a dict."""
    return _schema_of(SiteFile, "rockmech site file")


def render_site_schema() -> str:
    """Return the site schema as the text stored on disk."""
    return json.dumps(build_site_schema(), sort_keys=True, indent=2, ensure_ascii=False) + "\n"


def build_search_schema() -> Dict[str, Any]:
    """Return the JSON Schema of ``SearchSpec`` (draft 2020-12) as a dict."""
    return _schema_of(SearchSpec, "rockmech search spec")


def render_search_schema() -> str:
    """Return the search-spec schema as the text stored on disk."""
    return json.dumps(build_search_schema(), sort_keys=True, indent=2, ensure_ascii=False) + "\n"


def build_spec_schema(model: Type[BaseModel] = SpecFile) -> Dict[str, Any]:
    """Return the JSON Schema of the mechanism-spec file (draft 2020-12) as a dict.

    Parameters
    ----------
    model : type, optional
        The spec-file model (default ``SpecFile``; a test passes one with an extra typology).

    Returns
    -------
    dict
        Each mechanism is one of the typologies' models (``oneOf``). The reader also takes
        a key of another typology left empty (null, [] or false) as absent; the schema,
        stricter, does not list it.
    """
    return _schema_of(model, "rockmech mechanism spec")


def render_spec_schema() -> str:
    """Return the mechanism-spec schema as the text stored on disk."""
    return json.dumps(build_spec_schema(), sort_keys=True, indent=2, ensure_ascii=False) + "\n"


def build_retrofit_schema() -> Dict[str, Any]:
    """Return the JSON Schema of ``RetrofitSpec`` (draft 2020-12) as a dict."""
    return _schema_of(RetrofitSpec, "rockmech retrofit spec")


def render_retrofit_schema() -> str:
    """Return the retrofit-spec schema as the text stored on disk."""
    return json.dumps(build_retrofit_schema(), sort_keys=True, indent=2, ensure_ascii=False) + "\n"


def main(argv: Optional[List[str]] = None) -> int:
    """Write the schema files, or with ``--check`` report whether they are up to date.

    Parameters
    ----------
    argv : list of str, optional
        Command-line arguments (default: ``sys.argv[1:]``).

    Returns
    -------
    int
        Exit status: 0 on success, 1 when ``--check`` finds a file missing or different.
    """
    parser = argparse.ArgumentParser(
        prog="python -m shared_schema.export", description=__doc__.splitlines()[0]
    )
    parser.add_argument(
        "--check", action="store_true", help="exit 1 if the file differs; write nothing"
    )
    parser.add_argument(
        "--output", type=Path, default=SCHEMA_PATH, help=f"schema file (default: {SCHEMA_PATH})"
    )
    parser.add_argument(
        "--site-output",
        type=Path,
        default=SITE_SCHEMA_PATH,
        help=f"site schema file (default: {SITE_SCHEMA_PATH})",
    )
    parser.add_argument(
        "--search-output",
        type=Path,
        default=SEARCH_SCHEMA_PATH,
        help=f"search-spec schema file (default: {SEARCH_SCHEMA_PATH})",
    )
    parser.add_argument(
        "--spec-output",
        type=Path,
        default=SPEC_SCHEMA_PATH,
        help=f"mechanism-spec schema file (default: {SPEC_SCHEMA_PATH})",
    )
    parser.add_argument(
        "--retrofit-output",
        type=Path,
        default=RETROFIT_SCHEMA_PATH,
        help=f"retrofit-spec schema file (default: {RETROFIT_SCHEMA_PATH})",
    )
    args = parser.parse_args(argv)
    pairs = (
        (Path(args.output), render_schema()),
        (Path(args.site_output), render_site_schema()),
        (Path(args.search_output), render_search_schema()),
        (Path(args.spec_output), render_spec_schema()),
        (Path(args.retrofit_output), render_retrofit_schema()),
    )
    status = 0
    for output, text in pairs:
        if args.check:
            try:
                current = output.read_bytes().decode("utf-8")
            except FileNotFoundError:
                print(f"{output}: missing; run python -m shared_schema.export", file=sys.stderr)
                status = 1
                continue
            if current != text:
                print(f"{output}: out of date; run python -m shared_schema.export", file=sys.stderr)
                status = 1
                continue
            print(f"{output}: up to date")
            continue
        if output.is_file() and output.read_bytes().decode("utf-8") == text:
            print(f"{output}: up to date")  # nothing to write (a read-only install stays so)
            continue
        output.parent.mkdir(parents=True, exist_ok=True)
        write_atomic(output, text)
        print(f"wrote {output}")
    return status


if __name__ == "__main__":
    sys.exit(main())
