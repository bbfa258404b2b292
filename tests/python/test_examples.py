"""The Python examples (host/examples/python) run, on small data."""
import json
import os
import pathlib
import re
import shutil
import subprocess
import sys

import pytest

EXAMPLES = pathlib.Path(__file__).resolve().parents[2] / "host" / "examples" / "python"


def run(script, *args):
    result = subprocess.run([sys.executable, str(EXAMPLES / script), *map(str, args)], capture_output=True,
                            text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    return result.stdout


def test_build_and_query(tmp_path):
    out = run("build_and_query.py", "--out", tmp_path)
    assert (tmp_path / "walks.mmdb").stat().st_size > 0
    assert out.count("frame ") == 4


def test_social_force_crowd_writes_the_viewer_page(tmp_path):
    html, summary = tmp_path / "crowd.html", tmp_path / "crowd.json"
    out = run("social_force_crowd.py", "--agents", 12, "--seconds", 4, "--html", html, "--summary", summary)
    assert "viewer page" in out
    page = html.read_text()
    assert page.startswith("<!DOCTYPE html>") and "social force" in page
    figures = json.loads(summary.read_text())
    assert figures["agents"] == 12 and figures["ticks"] == 120
    # The page loads in headless Chromium and draws every character (the
    # viewer tests' check; without chromium it is skipped unless
    # MMVK_REQUIRE_VIEWER is set, as CI does).
    chromium = shutil.which("chromium")
    if chromium is None:
        if os.environ.get("MMVK_REQUIRE_VIEWER"):
            pytest.fail("chromium is not installed (MMVK_REQUIRE_VIEWER is set)")
        return
    dom = subprocess.run(
        ["timeout", "120", chromium, "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--window-size=1280,800", "--virtual-time-budget=10000", f"--user-data-dir={tmp_path / 'profile'}",
         "--dump-dom", f"file://{html}"], capture_output=True, text=True).stdout
    status = re.search(r'<div id="status"[^>]*>', dom)
    assert status and 'data-state="ready"' in status.group(0) and 'data-drawn="12"' in status.group(0), (
        status.group(0) if status else dom[:500])


def test_phase_sidecar(tmp_path):
    out = run("phase_sidecar.py", "--out", tmp_path)
    assert len(list(tmp_path.glob("*.phase.f32"))) == 8
    assert "'name': 'phase'" in out and (tmp_path / "with-phase.mmdb").exists()
