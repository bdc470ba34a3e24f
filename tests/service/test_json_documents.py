"""Every JSON document rockmech writes names its units and the version that wrote it (#27).

Walks every command with ``--json`` (found by introspecting the command line, so a new one
cannot be missed), the JSON files each run leaves in its output folder (the demo's too), every
endpoint of the live server that answers JSON (found from its OpenAPI document), and the
``json`` output of every Hops component. Each document must carry ``rockmech_version``
(``shared_schema.version.__version__``) and a non-empty ``units`` block. The run folder's own
bookkeeping (``.rockmech/manifest.json``, which names the version as ``rockmech``) is not a
result document.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import httpx
import pytest
import typer
from api_helpers import EXAMPLES, runner
from servers import Server
from test_hops import hops_payload, outputs

from shared_schema.documents.base import Document
from shared_schema.version import __version__
from solver_service.cli import app

WALLS = EXAMPLES / "constants" / "rect_walls.json"
GEOMETRY = EXAMPLES / "constants" / "church_geometry.json"
RECORD = EXAMPLES / "records" / "elcentro_NS.dat"
SITE = EXAMPLES / "sites" / "ntc_site.json"
SCENE = EXAMPLES / "scenes" / "rect_wall.3dm"
SPEC = EXAMPLES / "specs" / "rect_wall.spec.json"
SEARCH_SCENE = EXAMPLES / "scenes" / "search_facade.3dm"
SEARCH_SPEC = EXAMPLES / "specs" / "search_facade.search.json"
RETROFIT_SPEC = EXAMPLES / "specs" / "church.retrofit.json"


def _stamped(doc: Any, where: str) -> None:
    assert isinstance(doc, dict), where
    assert doc.get("rockmech_version") == __version__, where
    units = doc.get("units")
    assert isinstance(units, dict) and units, where
    assert all(isinstance(k, str) and isinstance(v, str) and v for k, v in units.items()), where


def _json_commands() -> set[str]:
    """Every command (and sub-command) with a ``--json`` option."""
    group = typer.main.get_command(app)
    found = set()

    def walk(cmd: Any, prefix: str) -> None:
        for name, sub in getattr(cmd, "commands", {}).items():
            walk(sub, f"{prefix} {name}".strip())
        if any("--json" in getattr(p, "opts", []) for p in getattr(cmd, "params", [])):
            found.add(prefix)

    walk(group, "")
    return found


@pytest.mark.slow
def test_every_command_and_file_names_units_and_version(tmp_path: Path) -> None:
    out = tmp_path
    runs = {
        "pulse": ["pulse", "--p-eq", "2", "--lam", "0.2", "--eta", "0.9", "--a-p-g", "0.3",
                  "--f-p", "1"],
        "history": ["history", str(WALLS), str(RECORD), "--scale", "0.5", "1",
                    "--out", str(out / "history")],
        "record": ["record", str(RECORD), "--out", str(out / "record")],
        "ida": ["ida", str(WALLS), str(RECORD), "--scales", "0.5,1", "--out", str(out / "ida")],
        "constants": ["constants", str(SCENE), str(SPEC), "-o", str(out / "constants.json")],
        "envelope": ["envelope", str(WALLS), "--n", "12", "--out", str(out / "envelope")],
        "boundary": ["boundary", "--omega", "5", "--eta", "0.9"],
        "check": ["check", str(GEOMETRY), str(SITE)],
        "assess": ["assess", str(GEOMETRY), str(SITE), "--record", str(RECORD),
                   "--multiple", "1", "-o", str(out / "assess.html")],
        "search": ["search", str(SEARCH_SCENE), str(SEARCH_SPEC), "--no-figure",
                   "-o", str(out / "search")],
        "retrofit": ["retrofit", str(GEOMETRY), "--site", str(SITE), "--spec",
                     str(RETROFIT_SPEC), "--out", str(out / "retrofit")],
    }  # fmt: skip
    assert set(runs) == _json_commands()
    for name, argv in runs.items():
        res = runner.invoke(app, [*argv, "--json"])
        assert res.exit_code == 0, (name, res.output)
        _stamped(json.loads(res.stdout), f"rockmech {name} --json")
    res = runner.invoke(app, ["demo", "--out", str(out / "demo")])
    assert res.exit_code == 0, res.output
    files = [p for p in out.rglob("*.json") if ".rockmech" not in p.parts]
    assert len(files) >= 10, files
    for path in files:
        doc = json.loads(path.read_text())
        if path.name.endswith(".spec.json"):
            # A mechanism spec (the search's, for `rockmech constants`): an input format whose
            # `units` names the unit of its points.
            assert doc.get("rockmech_version") == __version__, path
            assert doc.get("units") in ("m", "cm", "mm", "file"), path
            continue
        _stamped(doc, str(path.relative_to(out)))


def _json_operations(client: httpx.Client) -> set[tuple[str, str]]:
    """Every (method, path) of the service whose answer may be a JSON object."""
    spec = client.get("/api/v1/openapi.json").json()
    found = set()
    for path, ops in spec["paths"].items():
        for method, op in ops.items():
            content = op.get("responses", {}).get("200", {}).get("content", {})
            if "application/json" in content:
                found.add((method.upper(), path))
    return found


def _response_models() -> dict[tuple[str, str], Any]:
    """The typed document each route declares (``response_model``), by (method, path)."""
    from fastapi.routing import APIRoute

    from solver_service.api import routes

    return {
        (method, routes.API_PREFIX + route.path): route.response_model
        for module in routes.ROUTE_MODULES
        for route in module.router.routes
        if isinstance(route, APIRoute) and route.response_model is not None
        for method in route.methods
    }


def test_every_endpoint_and_hops_component_names_units_and_version(
    server: Server, client: httpx.Client, tmp_path: Path
) -> None:
    walls = json.loads(WALLS.read_text())
    geometry = json.loads(GEOMETRY.read_text())
    site = json.loads(SITE.read_text())
    record = {"accel": [0.0, 0.1, -0.2, 0.15, 0.0] * 40, "dt": 0.01, "units": "g", "name": "r"}
    scene = {
        "scene": (SCENE.name, SCENE.read_bytes(), "application/octet-stream"),
        "spec": (SPEC.name, SPEC.read_bytes(), "application/json"),
    }
    search_spec = {
        **json.loads(SEARCH_SPEC.read_text()),
        "ranking": {"keep": 3, "n_frequencies": 50},
    }
    calls = {
        ("GET", "/api/v1/health"): {},
        ("POST", "/api/v1/pulse"): {
            "json": {"p_eq": 2.0, "lam": 0.2, "eta": 0.9, "a_p_g": 0.3, "f_p": 1.0}
        },
        ("POST", "/api/v1/envelope"): {"json": {"constants": walls, "n": 12}},
        ("POST", "/api/v1/history"): {"json": {"constants": walls, "record": record}},
        ("POST", "/api/v1/spectrum"): {"json": {"record": record}},
        ("POST", "/api/v1/scale-factor"): {
            "json": {"method": "eq28", "h": 4.0, "h_e": 5.0, "sa_g": 0.3, "pga_g": 0.2}
        },
        ("POST", "/api/v1/constants"): {"files": scene},
        ("POST", "/api/v1/check"): {"json": {"constants": geometry, "site": site}},
        ("POST", "/api/v1/assess"): {
            "json": {"constants": geometry, "site": site, "records": [record], "multiples": [1]}
        },
        ("POST", "/api/v1/retrofit"): {
            "json": {
                "constants": geometry,
                "site": site,
                "spec": json.loads(RETROFIT_SPEC.read_text()),
            }
        },
        ("POST", "/api/v1/search"): {
            "files": {
                "scene": (SEARCH_SCENE.name, SEARCH_SCENE.read_bytes(), "application/octet-stream"),
                # The example's ranking names a site and a record by path: the service takes
                # uploads only, so this spec ranks without them.
                "spec": ("search.json", json.dumps(search_spec).encode(), "application/json"),
            }
        },
    }
    assert set(calls) == _json_operations(client)
    models = _response_models()
    validated = 0
    for (method, path), kwargs in calls.items():
        res = client.request(method, path, **kwargs)
        assert res.status_code == 200, (path, res.text[:300])
        _stamped(res.json(), f"{method} {path}")
        model = models.get((method, path))
        if isinstance(model, type) and issubclass(model, Document):
            # The declared document (extra="forbid") takes the answer, and gives it back
            # byte for byte (key order, ints, absent sections).
            doc = model.model_validate(res.json())
            assert doc.to_dict() == res.json(), path
            assert json.dumps(doc.to_dict()) == json.dumps(res.json()), path
            validated += 1
    assert validated >= 1
    hops = {
        "pulse": hops_payload(p_eq=2.0, lam=0.2, a_p_g=0.3, f_p=1.0, eta=0.9, one_sided=False,
                              shape="sine"),
        "envelope": hops_payload(constants=WALLS.read_text(), f_min=0.2, f_max=8.0, n=10),
        "history": hops_payload(constants=WALLS.read_text(), accel_g=record["accel"], dt=0.01,
                                scales=[1.0]),
    }  # fmt: skip
    assert {c["Uri"].strip("/") for c in client.get("/hops/").json()} == set(hops)
    for name, body in hops.items():
        out = outputs(client.post(f"/hops/{name}", json=body))
        _stamped(json.loads(out["json"][0]), f"hops {name}")
