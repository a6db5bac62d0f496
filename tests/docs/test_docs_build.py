"""The documentation builds with warnings as errors, holds its pages, and runs as written.

The build is the README's command (``python -m sphinx -W -b html docs …``, here with
``--keep-going`` to list every warning and ``-j 1`` on CI's shared cores); no network is
used (no intersphinx).
"""

from __future__ import annotations

import contextlib
import importlib.util
import io
import math
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
PAGES = (
    "index",
    "getting-started",
    "tutorials/stability-stable32",
    "tutorials/multipos-imucal",
    "tutorials/chamber-to-c",
    "tutorials/noise-for-estimator",
    "tutorials/fc-params",
    "tutorials/production-batch",
    "tutorials/notebook-poly",
    "methods",
    "cli",
    "api",
)

OUTSIDE = re.compile(r"\bSPEC\b|INTERFACE\.md|\.\./shared|\bissues?\s*#?\d+", re.IGNORECASE)
"""What a clone does not have: the project's working notes and its issue numbers."""


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The HTML documentation, built once for this module."""
    if importlib.util.find_spec("myst_parser") is None:
        pytest.fail(
            "myst-parser is missing: install the docs packages with "
            "pip install -c requirements/test.lock -e '.[dev]'"
        )
    out = tmp_path_factory.mktemp("docs-html")
    doctrees = tmp_path_factory.mktemp("docs-doctrees")
    cmd = [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-j", "1", "-q", "-b", "html"]
    proc = subprocess.run(
        [*cmd, "-d", str(doctrees), str(DOCS), str(out)],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
        cwd=ROOT,
    )
    assert proc.returncode == 0, proc.stderr
    assert "WARNING" not in proc.stderr and "ERROR" not in proc.stderr, proc.stderr
    return out


def test_every_page_is_built(built: Path) -> None:
    for page in PAGES:
        assert (built / f"{page}.html").is_file(), page
    index = (built / "index.html").read_text(encoding="utf-8")
    for page in PAGES[1:]:
        assert f'href="{page}.html"' in index, page  # in the table of contents


def test_methods_cite_their_sources_and_show_formulas(built: Path) -> None:
    text = (built / "methods.html").read_text(encoding="utf-8")
    for source in (
        "IEEE Std 952-1997",
        "IEEE Std 1293-1998",
        "IEEE Std 1431-2004",
        "IEEE Std 1554-2005",
        "NIST Special Publication 1065",
        "Greenhall and W. J. Riley",
        "Theo1",
        "total deviation approach",
        "Tedaldi, A. Pretto and E. Menegatti",
        "Ferraris, U. Grimaldi and M. Parvis",
        "Tools/process_sensor_caldata.py",
        "AP_InertialSensor_tempcal.cpp",
        "AP_TempCalibration.cpp",
        "CN104880182",
        "Adaptive accelerometer temperature compensation method for inertial navigation",
    ):
        assert source in text, source
    assert text.count('class="math notranslate nohighlight"') >= 30


def test_api_reference_documents_the_entry_points(built: Path) -> None:
    text = (built / "api.html").read_text(encoding="utf-8")
    for name in (
        "thermocal.read_recording",
        "thermocal.stability.allan.overlapping_adev",
        "thermocal.stability.allan.noise_terms",
        "thermocal.stability.family.stability",
        "thermocal.models.make_model",
        "thermocal.turntable.calibrate",
        "thermocal.multipos.calibrate.calibrate_session",
        "thermocal.export.params.export_params",
    ):
        assert f'id="{name}"' in text, name


def test_cli_reference_is_in_the_site(built: Path) -> None:
    text = (built / "cli.html").read_text(encoding="utf-8")
    for anchor in ("thermocal-fit", "thermocal-allan", "thermocal-station-run"):
        assert f'<section id="{anchor}"' in text, anchor


def test_docs_and_readme_name_nothing_outside_the_repository() -> None:
    suffixes = {".md", ".rst", ".py", ".txt"}
    docs = [p for p in DOCS.rglob("*") if "_build" not in p.parts and p.suffix in suffixes]
    files = [ROOT / "README.md", *sorted(docs)]
    assert len(files) >= 6
    found = [
        f"{path.relative_to(ROOT)}:{n}: {line.strip()}"
        for path in files
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
        if OUTSIDE.search(line)
    ]
    assert not found, found


def test_readme_states_the_docs_command() -> None:
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert "python -m sphinx -W -b html docs docs/_build/html" in readme


def _blocks(text: str, lang: str) -> list[tuple[int, str]]:
    return [
        (m.start(), m.group(1))
        for m in re.finditer(rf"^```{lang}\n(.*?)^```$", text, re.MULTILINE | re.DOTALL)
    ]


def _white_fm_edf(n_phase: int, m: int) -> float:
    """NIST SP 1065 Table 5 (Howe, Allan & Barnes): overlapping ADEV, white FM, written here."""
    return (3 * (n_phase - 1) / (2 * m) - 2 * (n_phase - 2) / n_phase) * 4 * m**2 / (4 * m**2 + 5)


def test_getting_started_python_runs_and_prints_what_the_page_says() -> None:
    page = (DOCS / "getting-started.md").read_text(encoding="utf-8")
    code = _blocks(page, "python")
    shown = _blocks(page, "text")
    assert len(code) == 1
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        exec(compile(code[0][1], "getting-started.md", "exec"), {})
    after = [text for pos, text in shown if pos > code[0][0]]
    assert printed.getvalue() == after[0]
    # and the numbers are right: white rate noise of σ = 1 has ADEV 1/√τ; each estimate lies
    # within 3 standard errors, 1/√(2·EDF), of it (N = 100 001 phase points)
    for line in printed.getvalue().splitlines():
        tau_s, unit, adev, _ = line.split()
        assert unit == "s"
        truth = 1 / math.sqrt(float(tau_s))
        edf = _white_fm_edf(100_001, int(float(tau_s)))
        assert abs(float(adev) - truth) < 3 * truth / math.sqrt(2 * edf), line
