"""The HTML report, rendered in a real headless Chromium: screenshot, and every plot loaded."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import httpx
import numpy as np
import pytest
from api_helpers import EXAMPLES, runner

from solver_service.cli import app

WALLS = EXAMPLES / "constants" / "rect_walls.json"
RECORD = EXAMPLES / "records" / "elcentro_NS.dat"
CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--no-first-run",
    "--disable-background-networking",
]
#: Seconds Chromium may take to load and render the page.
CHROMIUM_TIMEOUT_S = 120


def _chromium() -> str:
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    pytest.skip("no Chromium on this machine: install Debian's 'chromium' package to run this test")


def _render(page: Path, shot: Path) -> str:
    """Load ``page`` in headless Chromium; write a screenshot; return the DOM after load."""
    exe = _chromium()
    url = page.resolve().as_uri()
    subprocess.run(
        [exe, *CHROMIUM_FLAGS, "--window-size=1200,3000", f"--screenshot={shot}", url],
        check=True,
        capture_output=True,
        timeout=CHROMIUM_TIMEOUT_S,
    )
    dom = subprocess.run(
        [exe, *CHROMIUM_FLAGS, "--dump-dom", url],
        check=True,
        capture_output=True,
        timeout=CHROMIUM_TIMEOUT_S,
    )
    return dom.stdout.decode("utf-8")


def _check_screenshot(shot: Path) -> None:
    import matplotlib.image as mpimg

    pixels = mpimg.imread(shot)
    assert pixels.shape[0] > 1000 and pixels.shape[1] > 1000
    # A page with plots is far from blank: many distinct colours and a spread of brightness.
    grey = pixels[..., :3].mean(axis=2)
    assert float(grey.std()) > 0.05
    assert len(np.unique((pixels[..., :3] * 255).astype(np.uint8).reshape(-1, 3), axis=0)) > 100


@pytest.mark.slow  # the quick loop's budget: the whole suite (CI) runs it
def test_report_from_the_endpoint_loads_all_its_plots_in_chromium(
    client: httpx.Client, tmp_path: Path
) -> None:
    files = {
        "constants": (WALLS.name, WALLS.read_bytes()),
        "record": (RECORD.name, RECORD.read_bytes()),
    }
    res = client.post("/api/v1/report", files=files, data={"scales": ["0.5", "1", "2"]})
    assert res.status_code == 200, res.text
    page = tmp_path / "report.html"
    page.write_bytes(res.content)
    dom = _render(page, tmp_path / "report.png")
    loaded = re.search(r'data-plots-loaded="(\d+)/(\d+)"', dom)
    assert loaded is not None, dom[:500]
    assert loaded.group(1) == loaded.group(2) == "3"  # envelopes, record/spectrum, histories
    _check_screenshot(tmp_path / "report.png")


@pytest.mark.slow  # the quick loop's budget: the whole suite (CI) runs it
def test_cli_report_without_a_record_renders(tmp_path: Path) -> None:
    out = tmp_path / "walls.html"
    res = runner.invoke(app, ["report", str(WALLS), "-o", str(out), "--n", "50"])
    assert res.exit_code == 0, res.output
    text = out.read_text()
    assert "<h2>Time histories</h2>" not in text and "<h2>Kinematic constants</h2>" in text
    dom = _render(out, tmp_path / "walls.png")
    assert 'data-plots-loaded="1/1"' in dom
    _check_screenshot(tmp_path / "walls.png")


def test_cli_and_endpoint_give_the_same_report(client: httpx.Client, tmp_path: Path) -> None:
    args = ["--scale", "0.5", "--scale", "1", "--n", "40", "--title", "walls"]
    cli_page = tmp_path / "cli.html"
    res = runner.invoke(
        app, ["report", str(WALLS), "--record", str(RECORD), *args, "-o", str(cli_page)]
    )
    assert res.exit_code == 0, res.output
    files = {
        "constants": (WALLS.name, WALLS.read_bytes()),
        "record": (RECORD.name, RECORD.read_bytes()),
    }
    data = {"scales": ["0.5", "1"], "n": "40", "title": "walls"}
    api = client.post("/api/v1/report", files=files, data=data)
    assert api.status_code == 200, api.text

    def strip(text: str) -> str:
        return re.sub(r"generated \d{4}-\d{2}-\d{2} \d{2}:\d{2} UTC", "generated -", text)

    assert strip(api.text) == strip(cli_page.read_text())
