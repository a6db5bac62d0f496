"""The gallery (``docs/gallery.md``) shows every figure a report can draw.

The figure names are read from the report's code, not from the gallery's extension: every
``<img class="figure" id="…">`` of the report templates and of the modules that write HTML
(``report/``, ``fleet/``), and every key of the chamber report's figure set
(``fs.add("KEY", …)`` gives ``id="fig-KEY"``).  An id built from a template value
(``fig-{{ t.name }}``, ``dist-{{ loop.index }}``, ``{a}-figure``) matches any gallery name
of that form.  That each gallery figure is drawn and embedded in the built page is checked
on the built site by ``test_docs_build.py``.
"""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SRC = ROOT / "src" / "thermocal"
GALLERY = ROOT / "docs" / "gallery.md"
LOGS = ROOT / "docs" / "_ext" / "gallery_data"
FIGURE_ID = re.compile(r'class="figure" id="([^"]+)"')
FIGURE_SET_KEY = re.compile(r'fs\.add\(\s*"(\w+)"')
TEMPLATE_VALUE = re.compile(r"\{\{[^}]*\}\}|\{[^}]*\}")


def report_figure_names() -> set[str]:
    """Every figure id the report code can write, template values as ``<value>``."""
    names: set[str] = set()
    files = [*(SRC / "report").rglob("*.py"), *(SRC / "report" / "templates").glob("*.j2")]
    files += list((SRC / "fleet").rglob("*.py"))
    for path in files:
        text = path.read_text(encoding="utf-8")
        names |= {TEMPLATE_VALUE.sub("<value>", n) for n in FIGURE_ID.findall(text)}
        names |= {f"fig-{key}" for key in FIGURE_SET_KEY.findall(text)}
    names.discard("<value>")  # report.html.j2 writes the figure set's ids: f"fig-{key}" above
    return names


def gallery_names() -> list[str]:
    return re.findall(r"^```\{thermocal-figure\} (\S+)$", GALLERY.read_text(), re.MULTILINE)


def _shown(name: str, shown: list[str]) -> bool:
    pattern = re.escape(name).replace(re.escape("<value>"), r"[\w-]+")
    return any(re.fullmatch(pattern, s) for s in shown)


def test_report_figure_names_are_found() -> None:
    names = report_figure_names()
    # the chamber report's seven, the calibration's two, the triads', the batch's, tempcal's
    assert {"fig-profile", "fig-fit", "fig-allan", "fig-dynamic", "fig-drift"} <= names
    assert {"fig-bias-grid", "fig-allan-grid", "fig-poses", "fig-<value>", "dist-<value>"} <= names
    assert {"offset-residual", "ardupilot-baro-holdout", "<value>-figure"} <= names


def test_every_figure_a_report_draws_is_in_the_gallery() -> None:
    shown = gallery_names()
    assert len(shown) == len(set(shown))
    missing = sorted(n for n in report_figure_names() if not _shown(n, shown))
    assert not missing, missing


def test_the_gallery_logs_are_what_their_script_makes() -> None:
    spec = importlib.util.spec_from_file_location(
        "make_gallery_logs", LOGS / "make_gallery_logs.py"
    )
    assert spec is not None and spec.loader is not None
    make = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(make)
    assert (LOGS / "bench.ulg").read_bytes() == make.ulog()
    assert (LOGS / "baro.bin").read_bytes() == make.dataflash()
    assert sum(p.stat().st_size for p in LOGS.iterdir()) < 600_000
