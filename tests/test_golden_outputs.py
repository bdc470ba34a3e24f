"""A fixed set of outputs, before and after a change of the code's layout (#29).

Every command of the ``rockmech`` command line that gives a JSON document runs on the bundled
examples, and its document is compared with ``tests/golden/outputs.json``: every text, key and
integer exactly, the order of the keys and the type of every value (``1`` is not ``1.0``), every
float to ``FLOAT_RTOL`` (1e-12: the last bits of a float depend on the
machine's vector instructions, not on the code). Only what
depends on the clock or the machine is left out (``TIMING_KEYS``). A refactoring keeps this
test green without touching the file; a change that means to change results regenerates it
with ``python tests/test_golden_outputs.py --write`` and says why in its commit and the
CHANGELOG.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from solver_service.cli import app

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
GOLDEN = ROOT / "tests" / "golden" / "outputs.json"
#: Keys whose values depend on the clock, the machine or the run's folder: left out.
TIMING_KEYS = frozenset(
    {
        "runtime_s",
        "timings",
        "generated",
        "elapsed_s",
        "wall_s",
        "cpu_s",
        "library_file",
        "compute_s",
        "overhead_per_task_s",
        "span_s",
        "task_s",
        "overhead_fraction",
    }
)

#: Numbers may differ in their last bits between machines (numpy's SIMD paths, the order a
#: threaded library sums in): a float within this fraction of the stored one is the same.
#: Keys, texts, integers and booleans are compared exactly.
FLOAT_RTOL = 1e-12
#: ... relative to at least this magnitude: floats of rounding's own size (the relative
#: difference of two exact results, ~1e-16) agree to 1e-15 absolute.
FLOAT_FLOOR = 1e-3

C = EXAMPLES / "constants"
WALLS, CHURCH, GEOMETRY = C / "rect_walls.json", C / "church.json", C / "church_geometry.json"
RECORD = EXAMPLES / "records" / "elcentro_NS.dat"
SITE = EXAMPLES / "sites" / "ntc_site.json"


def commands(out: Path) -> dict[str, list[str]]:
    """The fixed set: name -> ``rockmech`` arguments (``--json`` is added)."""
    scene, spec = EXAMPLES / "scenes", EXAMPLES / "specs"
    return {
        "pulse": ["pulse", "--p-eq", "2", "--lam", "0.2", "--eta", "0.95", "--a-p-g", "0.282",
                  "--f-p", "0.32"],
        "pulse_one_sided": ["pulse", "--p-eq", "1.5", "--lam", "0.15", "--one-sided", "--eta", "0",
                            "--a-p-g", "0.4", "--f-p", "0.8"],
        "boundary": ["boundary", "--omega", "3", "--eta", "0.9"],
        "envelope_exact": ["envelope", str(CHURCH), "--n", "15", "--out", str(out / "e1")],
        "envelope_fast": ["envelope", str(GEOMETRY), "--n", "15", "--fast",
                          "--out", str(out / "e2")],
        "history": ["history", str(WALLS), str(RECORD), "--scale", "0.5", "1", "2",
                    "--out", str(out / "h")],
        "record": ["record", str(RECORD), "--out", str(out / "r")],
        "ida": ["ida", str(WALLS), str(RECORD), "--scales", "0.5,1,1.5,2", "--jobs", "1",
                "--out", str(out / "i")],
        "constants_facade": ["constants", str(scene / "facade.3dm"),
                             str(spec / "facade.spec.json"), "-o", str(out / "c1.json")],
        "constants_frame": ["constants", str(scene / "asym_frame.3dm"),
                            str(spec / "asym_frame.spec.json"), "-o", str(out / "c2.json")],
        "constants_side_aisle": ["constants", str(scene / "side_aisle.3dm"),
                                 str(spec / "side_aisle.spec.json"), "-o", str(out / "c3.json")],
        "constants_scan": ["constants", str(scene / "scan_wall.ply"),
                           str(spec / "scan_wall_ply.spec.json"), "--units", "mm",
                           "-o", str(out / "c4.json")],
        "check": ["check", str(GEOMETRY), str(SITE)],
        "assess": ["assess", str(GEOMETRY), str(SITE), "--record", str(RECORD),
                   "--multiple", "1", "--multiple", "2", "-o", str(out / "a.html")],
        "search": ["search", str(scene / "search_facade.3dm"),
                   str(spec / "search_facade.search.json"), "--no-figure", "-o", str(out / "s")],
    }  # fmt: skip


def _strip(doc: Any) -> Any:
    if isinstance(doc, dict):
        return {k: _strip(v) for k, v in doc.items() if k not in TIMING_KEYS}
    if isinstance(doc, list):
        return [_strip(v) for v in doc]
    return doc


def run_all(out: Path) -> dict[str, Any]:
    """Run the fixed set and return each document without its clock-dependent keys."""
    runner = CliRunner()
    docs = {}
    for name, argv in commands(out).items():
        res = runner.invoke(app, [*argv, "--json"])
        assert res.exit_code == 0, (name, res.output)
        docs[name] = _strip(json.loads(res.stdout))
    return docs


def _differences(old: Any, new: Any, where: str = "") -> list[str]:
    if isinstance(old, dict) and isinstance(new, dict):
        out = [f"{where}.{k}: only before" for k in old.keys() - new.keys()]
        out += [f"{where}.{k}: only after" for k in new.keys() - old.keys()]
        before, after = [k for k in old if k in new], [k for k in new if k in old]
        if before != after:
            out.append(f"{where}: keys in another order: {before} -> {after}")
        for k in old.keys() & new.keys():
            out += _differences(old[k], new[k], f"{where}.{k}")
        return out
    if isinstance(old, list) and isinstance(new, list) and len(old) == len(new):
        return [
            d for i, (a, b) in enumerate(zip(old, new)) for d in _differences(a, b, f"{where}[{i}]")
        ]
    if type(old) is not type(new):  # 1 and 1.0 are different documents
        was, now = type(old).__name__, type(new).__name__
        return [f"{where}: {was} {str(old)[:60]} -> {now} {str(new)[:60]}"]
    if isinstance(old, float) and isinstance(new, float) and old != new:
        if abs(old - new) <= FLOAT_RTOL * max(abs(old), abs(new), FLOAT_FLOOR):
            return []
    return [] if old == new else [f"{where}: {str(old)[:80]} -> {str(new)[:80]}"]


def test_the_fixed_outputs_are_unchanged_bit_for_bit(tmp_path: Path) -> None:
    if not (EXAMPLES / "scenes" / "facade.3dm").is_file():
        pytest.skip("the bundled .3dm examples are missing")
    golden = json.loads(GOLDEN.read_text(encoding="utf-8"))
    now = run_all(tmp_path)
    assert set(now) == set(golden["documents"])
    diffs = [d for name in now for d in _differences(golden["documents"][name], now[name], name)]
    assert not diffs, (
        f"{len(diffs)} differences from tests/golden/outputs.json (first 20):\n"
        + "\n".join(diffs[:20])
        + "\nA change meant to change results: python tests/test_golden_outputs.py --write"
    )


if __name__ == "__main__":
    import tempfile

    if sys.argv[1:] != ["--write"]:
        raise SystemExit("usage: python tests/test_golden_outputs.py --write")
    with tempfile.TemporaryDirectory() as d:
        documents = run_all(Path(d))
    GOLDEN.parent.mkdir(exist_ok=True)
    # One line per document (git stores it compressed; the test prints the differences).
    # The keys in the order the document has them: the test compares that order too.
    lines = [f" {json.dumps(k)}: {json.dumps(v)}" for k, v in documents.items()]
    about = "tests/test_golden_outputs.py: the fixed set's documents, bit for bit"
    text = '{"about": ' + json.dumps(about) + ',\n"documents": {\n' + ",\n".join(lines) + "\n}}\n"
    GOLDEN.write_text(text, encoding="utf-8")
    print(f"wrote {GOLDEN.relative_to(ROOT)}: {len(documents)} documents")
