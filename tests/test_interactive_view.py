"""The campaign's interactive view (campaign.interactive) in headless Chromium: the page loads
from the file alone without a console error, the linked figures render every sample, and a box
selection dragged with the mouse over the footprint marks the samples in both scatters, draws
their trajectories and lists their inputs; a double click clears it.

The browser is the system's Chromium (Debian's package; .ci/run installs it) driven by
Playwright. Without it the test is skipped, unless DRAKE_ENTRY_REQUIRE_BROWSER is set (CI sets
it: there a missing browser is a failure)."""
import json
import os
import shutil

import numpy as np
import pytest

from drake_entry.campaign.interactive import INTERACTIVE, closest_margins, write_interactive

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
REQUIRED = bool(os.environ.get("DRAKE_ENTRY_REQUIRE_BROWSER"))


def _campaign(n=40, seed=2):
    """Rows and stored trajectories of a synthetic campaign: every fifth sample failed."""
    rng = np.random.default_rng(seed)
    ok = [i % 5 != 0 for i in range(n)]
    rows = {"index": list(range(n)), "success": ok,
            "message": ["reached E_f" if s else "outside the acceptance box: distance error +3 km" for s in ok],
            "err_crossrange_m": rng.normal(0, 800, n).tolist(), "err_range_m": rng.normal(0, 800, n).tolist(),
            "margin_heat_flux": rng.uniform(0.01, 0.2, n).tolist(), "margin_normal_load": rng.uniform(-0.05, 0.3, n).tolist(),
            "margin_bank": [0.5] * n, "disp_density_scale": rng.normal(1, 0.05, n).tolist(),
            "disp_dV_m_s": rng.normal(0, 5, n).tolist()}
    t = np.linspace(0, 1500, 300)
    traj = {"sample": [], "time_s": [], "altitude_m": [], "velocity_m_s": [], "bank_deg": []}
    for i in range(n):
        traj["sample"] += [i] * t.size
        traj["time_s"] += t.tolist()
        traj["velocity_m_s"] += (7400 * (1 - t / 1700)).tolist()
        traj["altitude_m"] += (120e3 - 70 * t + 300 * i).tolist()
        traj["bank_deg"] += (60 * np.sin(t / 200 + i)).tolist()
    return rows, traj


def test_the_view_carries_every_sample_the_closest_margins_and_labelled_inputs(tmp_path):
    rows, traj = _campaign()
    assert closest_margins(rows, 40) == ["margin_normal_load", "margin_heat_flux"]
    path = write_interactive(str(tmp_path), rows, traj, None, "synthetic", labels={"disp_density_scale": "density factor"})
    text = open(path).read()
    data = json.loads(text.split("const D = ", 1)[1].split(";\nconst N", 1)[0])
    assert data["index"] == list(range(40)) and data["success"][0] is False
    assert [m["name"] for m in data["margins"]] == ["normal load", "heat flux"]
    assert data["margins"][0]["values"][3] == pytest.approx(100 * rows["margin_normal_load"][3], abs=1e-4)
    assert [c["name"] for c in data["inputs"]] == ["dV_m_s", "density factor"]
    assert len(data["trajectories"]["7"]["h"]) <= 150 and data["trajectories"]["7"]["t"][-1] == 1500.0
    assert "https://" not in text.split("<script>", 1)[0] and "src=\"http" not in text  # nothing fetched


@pytest.mark.skipif(CHROMIUM is None and not REQUIRED, reason="no system Chromium (Debian package chromium)")
def test_in_headless_chromium_a_mouse_selection_shows_the_trajectories_and_inputs(tmp_path):
    sync_api = pytest.importorskip("playwright.sync_api") if not REQUIRED else __import__(
        "playwright.sync_api", fromlist=["sync_playwright"])
    assert CHROMIUM, "DRAKE_ENTRY_REQUIRE_BROWSER is set but no chromium is installed"
    rows, traj = _campaign()
    path = write_interactive(str(tmp_path), rows, traj, None, "synthetic")
    assert os.path.basename(path) == INTERACTIVE
    with sync_api.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=[
            "--no-sandbox", "--disable-gpu", "--disable-background-networking", "--disable-component-update",
            "--disable-sync", "--no-first-run"])
        try:
            page = browser.new_page(viewport={"width": 1400, "height": 1200})
            problems = []
            page.on("console", lambda m: problems.append(m.text) if m.type in ("error", "warning") else None)
            page.on("pageerror", lambda e: problems.append(str(e)))
            page.on("request", lambda r: problems.append(f"fetched {r.url}") if not r.url.startswith("file:") else None)
            page.goto(f"file://{path}")
            page.wait_for_function("document.querySelectorAll('#traj .main-svg').length > 0")
            assert page.evaluate("document.querySelectorAll('#footprint .point').length") == 40
            assert page.evaluate("document.querySelectorAll('#margins .point').length") == 40
            assert page.evaluate("document.getElementById('traj').data[1].x.length") == 0
            # a box selection over the whole footprint, dragged with the mouse
            page.evaluate("Plotly.relayout('footprint', {dragmode: 'select'})")
            box = page.locator("#footprint .nsewdrag").bounding_box()
            page.mouse.move(box["x"] + 2, box["y"] + 2)
            page.mouse.down()
            page.mouse.move(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2, steps=5)
            page.mouse.move(box["x"] + box["width"] - 2, box["y"] + box["height"] - 2, steps=5)
            page.mouse.up()
            page.wait_for_function("document.querySelectorAll('#table tr').length > 1")
            selected = page.evaluate("document.getElementById('margins').data[0].selectedpoints")
            assert len(selected) == 40  # marked in the other scatter too
            points = page.evaluate("document.getElementById('traj').data[1].x.length")
            assert points == 40 * (150 + 1)  # every selected trajectory drawn (150 points and a break each)
            assert page.evaluate("document.querySelectorAll('#table tr.failed').length") == 8
            assert "40 sample(s) selected." in page.inner_text("#count")
            page.evaluate("window.showSamples([3])")
            assert page.evaluate("document.getElementById('traj').data[1].x.length") == 151
            assert page.evaluate("document.querySelectorAll('#table tr').length") == 2
            assert problems == []
        finally:
            browser.close()
