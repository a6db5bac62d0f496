"""Checks of a written HTML report shared by the report and demo tests: its tagged numbers,
its embedded PNG figures, and a real headless-Chromium rendering (screenshot, DOM after
load, console errors)."""

from __future__ import annotations

import base64
import html
import os
import re
import shutil
import subprocess
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from thermocal.report import fmt_num

CHROMIUM = Path("/usr/bin/chromium")


def tagged_numbers(text: str) -> dict[str, tuple[str, str]]:
    """``data-key`` → (``data-value``, displayed text) of every tagged number."""
    out = {}
    pat = re.compile(r'<span class="num" data-key="([^"]*)" data-value="([^"]*)">([^<]*)</span>')
    for key, value, shown in pat.findall(text):
        out[html.unescape(key)] = (html.unescape(value), html.unescape(shown))
    return out


def check_number(
    tags: dict[str, tuple[str, str]], key: str, expected: float, rel: float = 1e-15
) -> None:
    """The tagged value equals ``expected`` (a JSON value: exactly; an independently
    computed reference: to ``rel``) and the shown text is its rounding."""
    assert key in tags, f"{key} not in report"
    value, shown = tags[key]
    assert float(value) == pytest.approx(expected, rel=rel, abs=0.0), key
    assert shown == fmt_num(expected, len(shown.replace("-", "").replace(".", "")) or 4) or (
        float(shown) == pytest.approx(expected, rel=5e-3)
    ), (key, shown, expected)


def png_size(data: bytes) -> tuple[int, int]:
    """Width and height of a PNG from its IHDR chunk (checks the signature)."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    assert data[12:16] == b"IHDR"
    return int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")


def embedded_pngs(text: str) -> dict[str, bytes]:
    out = {}
    for fid, b64 in re.findall(
        r'<img class="figure" id="([^"]+)" src="data:image/png;base64,([^"]+)"', text
    ):
        out[fid] = base64.b64decode(b64)
    return out


def chromium_available() -> bool:
    return CHROMIUM.exists()


def skip_without_chromium() -> None:
    """Skip only when Chromium is absent AND not in CI (in CI the test must run), or
    when ``.ci/run`` reported that installing it failed (the skip then says so)."""
    if chromium_available():
        return
    failed = os.environ.get("THERMOCAL_CHROMIUM_INSTALL_FAILED")
    if failed:
        pytest.skip(f"chromium could not be installed by .ci/run: {failed}")
    if not os.environ.get("CI"):
        pytest.skip("/usr/bin/chromium is not installed (install Debian's chromium)")


def run_chromium(report: Path, tmp: Path) -> dict[str, Any]:
    """Render ``report`` headless: screenshot PNG, DOM after load, console errors."""
    exe = str(CHROMIUM) if CHROMIUM.exists() else (shutil.which("chromium") or str(CHROMIUM))
    common = [
        exe,
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--disable-dev-shm-usage",
        "--hide-scrollbars",
        "--enable-logging=stderr",
        "--v=0",
    ]
    url = report.resolve().as_uri()
    shot = tmp / "screenshot.png"
    env = {**os.environ, "HOME": str(tmp)}
    p1 = subprocess.run(
        [
            *common,
            f"--user-data-dir={tmp / 'profile1'}",
            f"--screenshot={shot}",
            "--window-size=1280,4000",
            "--virtual-time-budget=5000",
            url,
        ],
        capture_output=True,
        text=True,
        timeout=120,
        env=env,
        check=False,
    )
    p2 = subprocess.run(
        [
            *common,
            f"--user-data-dir={tmp / 'profile2'}",
            "--virtual-time-budget=5000",
            "--dump-dom",
            url,
        ],
        capture_output=True,
        text=True,
        timeout=120,
        env=env,
        check=False,
    )
    stderr = p1.stderr + p2.stderr
    # Chromium logs every console message (log, warn, error, uncaught exceptions) as
    # "…:CONSOLE(…)] "text", source: …"; the report writes none, so any is an error.
    lines = stderr.splitlines()
    console = [ln for ln in lines if ":CONSOLE" in ln or "Uncaught" in ln]
    console += [ln for ln in lines if "Content Security Policy" in ln]
    return {
        "screenshot": shot,
        "dom": p2.stdout,
        "console_errors": console,
        "returncodes": (p1.returncode, p2.returncode),
        "stderr": stderr,
    }


def screenshot_stats(path: Path) -> tuple[int, int, float, int]:
    """Width, height, std of the grey level [0-255] and number of distinct grey levels
    of a PNG screenshot (a blank page has std ≈ 0 and one level)."""
    import matplotlib.image as mpimg

    png_size(path.read_bytes())  # a real PNG
    img = np.asarray(mpimg.imread(path), dtype=np.float64)  # (h, w, 3|4) in [0, 1]
    grey = img[:, :, :3].mean(axis=2) * 255.0
    h, w = grey.shape
    return w, h, float(grey.std()), int(np.unique(np.round(grey)).size)


def check_rendered(result: dict[str, Any], n_figures_min: int) -> str:
    """Assertions shared by the report and demo browser tests; returns the DOM."""
    assert result["returncodes"] == (0, 0), result["stderr"][-2000:]
    assert not result["console_errors"], result["console_errors"]
    dom = result["dom"]
    body = re.search(r"<body([^>]*)>", dom)
    assert body is not None
    attrs = dict(re.findall(r'([\w-]+)="([^"]*)"', body.group(1)))
    assert attrs.get("data-loaded") == "1", attrs
    total = int(attrs["data-images-total"])
    assert total >= n_figures_min
    assert int(attrs["data-images-ok"]) == total, attrs.get("data-images-bad")
    for img in re.findall(r"<img[^>]*>", dom):
        assert 'data-loaded="1"' in img
        width = re.search(r'data-natural-width="(\d+)"', img)
        assert width is not None and int(width.group(1)) > 100
    w, h, std, levels = screenshot_stats(result["screenshot"])
    assert (w, h) == (1280, 4000)
    assert std > 10.0 and levels > 20, (std, levels)  # not a blank page
    return str(dom)
