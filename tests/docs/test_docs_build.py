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
    "tutorials/notebook-allan",
    "tutorials/multipos-imucal",
    "tutorials/notebook-multipos",
    "tutorials/chamber-to-c",
    "tutorials/noise-for-estimator",
    "tutorials/fc-params",
    "tutorials/notebook-px4",
    "tutorials/production-batch",
    "tutorials/station",
    "tutorials/notebook-poly",
    "tutorials/ros-bags",
    "methods",
    "gallery",
    "cli",
    "json",
    "api",
)

OUTSIDE = re.compile(
    r"\bSPEC\b"  # the project's working notes …
    r"|INTERFACE\.md|\.\./shared|STYLE rule"
    r"|\b[Ii]ssues?\s*#?\d+"  # … its issue numbers: "issue 40", "issues 12", "issue #40",
    r"|(?<![\w&\"'])#\d{1,4}\b"  # "#40" (not a colour such as "#888888" or "#111")
    r"|\b[Ss]ession\s+\d+\b(?!\.\d)"  # "session 8" (not "the session 1.1 mg")
    r"|\bh[1-9]\d(?!\d)"  # and its helpers' names, "h38"
)
"""What a clone does not have: the project's working notes, its issue numbers and the names
of its working sessions."""

SCANNED = {".md", ".rst", ".py", ".txt", ".toml", ".j2", ".html", ".c", ".h"}
"""The suffixes of text a user reads: pages, sources, templates, generated C."""


def outside_citations(folder: Path) -> list[str]:
    """``path:line: text`` of every line under ``folder`` (or of the file ``folder``) that
    cites something a clone does not have (:data:`OUTSIDE`); build outputs are skipped."""
    paths = [folder] if folder.is_file() else sorted(folder.rglob("*"))
    files = [p for p in paths if p.suffix in SCANNED and p.is_file() and "_build" not in p.parts]
    return [
        f"{path.relative_to(ROOT) if path.is_relative_to(ROOT) else path}:{n}: {line.strip()}"
        for path in files
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
        if OUTSIDE.search(line)
    ]


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


SOURCES = {
    # how the code names a published source → how the methods' References name it
    r"IEEE Std 952|IEEE 952": "IEEE Std 952-1997",
    r"IEEE Std 1293|IEEE 1293": "IEEE Std 1293-1998",
    r"IEEE Std 1431|IEEE 1431": "IEEE Std 1431-2004",
    r"IEEE Std 1554|IEEE 1554": "IEEE Std 1554-2005",
    r"SP 1065|SP1065": "NIST Special Publication 1065",
    r"Greenhall": "Greenhall and W. J. Riley",
    r"Riley & Greenhall|Riley and Greenhall": "W. J. Riley and C. A. Greenhall",
    r"Howe & Peppler|Howe and Peppler": "Howe and T. K. Peppler",
    r"Howe & Tasset|Howe and Tasset": "Howe and T. N. Tasset",
    r"Tedaldi": "Tedaldi, A. Pretto and E. Menegatti",
    r"Ferraris": "Ferraris, U. Grimaldi and M. Parvis",
    r"Gorini": "Ferraris, I. Gorini, U. Grimaldi and M. Parvis",
    r"process_sensor_caldata": "Tools/process_sensor_caldata.py",
    r"TemperatureCompensation\.cpp": "TemperatureCompensation.cpp",
    r"AP_InertialSensor_tempcal": "AP_InertialSensor_tempcal.cpp",
    r"AP_TempCalibration": "AP_TempCalibration.cpp",
    r"Kalibr|kalibr": "Extending kalibr",
    r"Barnes'? B1|Barnes 1969": "NBS Technical Note 375",
    r"Welch": "P. D. Welch",
    r"Hampel": "F. R. Hampel",
    r"Iglewicz": "B. Iglewicz and D. C. Hoaglin",
    r"Golub": "G. H. Golub and C. F. Van Loan",
    r"WGS-?84|TR8350": "NIMA TR8350.2",
    r"OWASP": "CSV Injection",
    r"Lawson": "C. L. Lawson and R. J. Hanson",
    r"Galleani": "L. Galleani and P. Tavella",
    r"Kalman 1960|R\. E\. Kalman": "R. E. Kalman",
    r"Schwarz": "G. Schwarz",
    r"Sokal": "A. D. Sokal",
    r"Kay 1993": "S. M. Kay",
    r"Floyd": "R. W. Floyd and R. L. Rivest",
    r"Buitinck": "L. Buitinck",
    r"FIPS 180|FIPS PUB 180": "FIPS PUB 180-4",
    r"RFC 4180": "RFC 4180",
    r"heater_params\.c": "heater_params.c",
    r"AP_BoardConfig\.cpp": "AP_BoardConfig.cpp",
    r"Niu et al|X\. Niu": "X. Niu, Y. Li, H. Zhang, Q. Wang and Y. Ban",
    r"Kim & Jung|Kim and Jung": "Kim and Jung (2025)",
    r"Franklin": "G. F. Franklin, J. D. Powell and M. L. Workman",
    r"Pereyra": "G. H. Golub and V. Pereyra",
    r"Bayley": "G. V. Bayley and J. M. Hammersley",
    r"R\. P\. Brent": "R. P. Brent",
    r"Student 1908|Student, \"The probable": 'Student, "The probable error of a mean"',
}
"""Every published source the package's code cites, and the methods chapter's entry for it."""


def test_methods_cite_every_source_the_code_cites() -> None:
    code = "\n".join(p.read_text(encoding="utf-8") for p in (ROOT / "src").rglob("*.py"))
    methods = (DOCS / "methods.md").read_text(encoding="utf-8")
    cited = [pattern for pattern in SOURCES if re.search(pattern, code)]
    assert len(cited) >= 15
    missing = [SOURCES[p] for p in cited if SOURCES[p] not in methods]
    assert not missing, missing


def test_api_reference_documents_the_entry_points(built: Path) -> None:
    text = (built / "api.html").read_text(encoding="utf-8")
    for name in (
        "thermocal.read_recording",
        "thermocal.stability.allan.overlapping_adev",
        "thermocal.stability.allan.noise_terms",
        "thermocal.stability.family.stability",
        "thermocal.stability.api.deviation",
        "thermocal.stability.api.oadev",
        "thermocal.stability.api.allan_noise",
        "thermocal.stability.registry.register",
        "thermocal.models.make_model",
        "thermocal.turntable.calibrate",
        "thermocal.multipos.calibrate.calibrate_session",
        "thermocal.export.params.export_params",
    ):
        assert f'id="{name}"' in text, name


def test_gallery_embeds_every_figure_it_names(built: Path) -> None:
    page = (DOCS / "gallery.md").read_text(encoding="utf-8")
    names = re.findall(r"^```\{thermocal-figure\} (\S+)$", page, re.MULTILINE)
    text = (built / "gallery.html").read_text(encoding="utf-8")
    assert len(names) >= 18
    for name in names:
        figure = re.search(rf'<figure[^>]* id="gallery-{re.escape(name)}">\s*<img [^>]*>', text)
        assert figure is not None, name
        assert 'src="data:image/png;base64,' in figure.group(0), name


def test_cli_reference_is_in_the_site(built: Path) -> None:
    text = (built / "cli.html").read_text(encoding="utf-8")
    for anchor in ("thermocal-fit", "thermocal-allan", "thermocal-station-run"):
        assert f'<section id="{anchor}"' in text, anchor


CITATION_CHECKED = (
    ROOT / "src",
    DOCS,
    ROOT / "README.md",
    ROOT / "CONTRIBUTING.md",
    ROOT / "ARCHITECTURE.md",
)
"""Where no outside citation may stand: the package, its documentation and the guides."""


@pytest.mark.parametrize("where", CITATION_CHECKED, ids=lambda p: p.name)
def test_nothing_cites_a_file_outside_the_repository(where: Path) -> None:
    found = outside_citations(where)
    assert not found, found


@pytest.mark.parametrize(
    "line",
    [
        "the contract in ../shared/INTERFACE.md",
        "bias (SPEC §1.2)",
        "see INTERFACE.md common rules",
        "as STYLE rule 8 says",
        "fixed in issue 40",
        "Issues 12 and 13",
        "closes issue #40",
        "(#40)",
        "found in session 8",
        "Session 12's attack",
        "h38 audit",
        "mutant h39mp-scale",
    ],
)
def test_the_citation_check_catches_each_kind(tmp_path: Path, line: str) -> None:
    (tmp_path / "pkg").mkdir()
    (tmp_path / "pkg" / "mod.py").write_text(f'"""Clean.\n\n{line}\n"""\n', encoding="utf-8")
    assert [f.split(":", 2)[1] for f in outside_citations(tmp_path / "pkg")] == ["3"]


@pytest.mark.parametrize(
    "line",
    [
        'ax.axhline(0.0, color="#888888")',
        "color='#111'",
        "imucal's session 1.1 mg, a simulated one 0.07 mg",
        "the noise coefficients h0, h-1 and h2 of NIST SP 1065",
        "a specification of the chamber",
        "## 2. The model",
    ],
)
def test_the_citation_check_passes_ordinary_text(tmp_path: Path, line: str) -> None:
    (tmp_path / "page.md").write_text(f"{line}\n", encoding="utf-8")
    assert outside_citations(tmp_path) == []


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
