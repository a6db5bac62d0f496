"""The gallery of the report's figures, drawn when the documentation is built.

``.. thermocal-figure:: ID`` shows the figure whose ``<img class="figure" id="ID">`` the
HTML reports of thermocal hold, with the directive's content as its caption.  The first
such directive of a build runs :data:`SCENARIOS` — thermocal's own commands on simulated
data and on the public recordings shipped in ``tests/data`` — in a temporary folder, reads
every figure out of the reports they write and keeps them for the build; nothing is
written into the source tree, and the figures are embedded in the page (as the reports
embed them).  A figure ID that no scenario draws is an error of the build.

The same scenarios are what a user runs, so the gallery shows exactly what a report of
this version draws.
"""

from __future__ import annotations

import contextlib
import io
import re
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

from docutils import nodes
from sphinx.application import Sphinx
from sphinx.util.docutils import SphinxDirective

ROOT = Path(__file__).resolve().parents[2]
FERRARIS = ROOT / "tests" / "data" / "imucal_ferraris"
LOGS = Path(__file__).resolve().parent / "gallery_data"
IMG = re.compile(r'<img class="figure" id="([^"]+)" src="(data:image/png;base64,[^"]+)"')

FLEET_TOML = """[fit]
model = "poly"
order = 3
signal = "gyro"
temps = "T1"

[limits]
rms_residual_max = 0.45
""" + "".join(f'\n[[unit]]\nid = "SN{n}"\nmodeling = ["SN{n}.csv"]\n' for n in range(1, 7))


def _chamber(run: Callable[..., str], here: Path) -> list[Path]:
    """The chamber workflow's report: a ring-laser gyro, its model and its validation."""
    run("simulate", "rlg-modelling", "-o", "mod.csv", "--rate-hz", "0.05", "--seed", "1")
    run("simulate", "rlg-validation", "-o", "val.csv", "--rate-hz", "0.05", "--seed", "2")
    site = ("--latitude", "45", "--axis", "up")
    run("fit", "mod.csv", "--model", "poly", "--order", "3", "--signal", "gyro",
        "--temps", "T1", *site, "-o", "poly.json")  # fmt: skip
    validate = ("validate", "poly.json", "val.csv", "--modeling", "mod.csv", "--ambient")
    (here / "validation.json").write_text(run(*validate, "T_chamber", "--json"))
    run("report", "--model", "poly.json", "--validation", "validation.json",
        "--recording", "val.csv", "--modeling", "mod.csv", "--dynamic", "20000",
        "-o", "chamber.html")  # fmt: skip
    return [here / "chamber.html"]


def _imu(run: Callable[..., str], here: Path) -> list[Path]:
    """A six-channel calibration's report (``demo --imu``)."""
    run("demo", "--imu", "--quick", "-o", "imu")
    return [here / "imu" / "report.html"]


def _triads(run: Callable[..., str], here: Path) -> list[Path]:
    """Triads over temperature (turntable soaks) and without a turntable (imucal's session)."""
    run("simulate", "turntable-thermal", "-o", "tt/run.parquet")
    soaks = [f"tt/run_T{t}.parquet" for t in ("-40", "-20", "+0", "+20", "+40", "+60")]
    run("turntable", *soaks, "--temps", "T_imu", "--accel", "accel_x,accel_y,accel_z",
        "-o", "tt/cal.json")  # fmt: skip
    run("report", "--model", "tt/cal.json", "--recording", "tt/run_heldout_T+10.parquet",
        "-o", "turntable.html")  # fmt: skip
    session = str(FERRARIS / "example_ferraris_session.csv")
    run("multipos", session, "--poses", str(FERRARIS / "example_ferraris_session_list.json"),
        "--rate", "102.4", "--accel", "acc_x,acc_y,acc_z", "--accel-unit", "m/s^2",
        "--gyro", "gyr_x,gyr_y,gyr_z", "--gyro-unit", "deg/s", "--gravity", "9.81",
        "-o", "mp.json")  # fmt: skip
    run("report", "--model", "mp.json", "--recording", session, "--rate", "102.4",
        "-o", "multipos.html")  # fmt: skip
    return [here / "turntable.html", here / "multipos.html"]


def _fleet(run: Callable[..., str], here: Path) -> list[Path]:
    """A production batch of six fibre-optic gyros."""
    for n in range(1, 7):
        run("simulate", "fog-slow", "-o", f"SN{n}.csv", "--seed", str(n), "--rate-hz", "0.05")
    (here / "batch.toml").write_text(FLEET_TOML)
    run("fleet", "batch.toml", "-o", "batch", "--workers", "1")
    return [here / "batch" / "fleet.html"]


def _tempcal(run: Callable[..., str], here: Path) -> list[Path]:
    """Flight-controller logs (``gallery_data/make_gallery_logs.py``): PX4 with a barometer,
    a magnetometer and an older calibration active; ArduPilot with a barometer."""
    run("px4-tempcal", str(LOGS / "bench.ulg"), "-o", "px4")
    run("ardupilot-tempcal", str(LOGS / "baro.bin"), "-o", "ardupilot")
    return sorted((here / "px4").glob("*.html")) + sorted((here / "ardupilot").glob("*.html"))


def _ratetable(run: Callable[..., str], here: Path) -> list[Path]:
    """A gyro's rate ladder at three temperatures (``simulate ratetable``)."""
    run("simulate", "ratetable", "--runs", "3", "-o", "rt")
    ladders = [f"rt/ratetable_T{t}.csv" for t in ("-20", "+20", "+60")]
    run("ratetable", *ladders, "--rate-column", "table_rate", "--temps", "temp",
        "--report", "ratetable.html")  # fmt: skip
    return [here / "ratetable.html"]


def _tumble(run: Callable[..., str], here: Path) -> list[Path]:
    """An accelerometer's tumble on a dividing head (``simulate tumble``)."""
    run("simulate", "tumble", "-o", "tb.csv")
    run("tumble", "tb.csv", "--angle-column", "angle", "--report", "tumble.html")
    return [here / "tumble.html"]


SCENARIOS: tuple[Callable[[Callable[..., str], Path], list[Path]], ...] = (
    _chamber,
    _imu,
    _triads,
    _ratetable,
    _tumble,
    _fleet,
    _tempcal,
)
"""Each runs commands in the scratch folder and returns the reports it wrote."""


def draw_figures() -> dict[str, str]:
    """Figure id → its PNG as a ``data:`` URI, from the reports of every scenario."""
    from thermocal.cli import main

    with tempfile.TemporaryDirectory(prefix="thermocal-gallery-") as tmp:
        here = Path(tmp)

        def run(*args: str) -> str:
            out, err = io.StringIO(), io.StringIO()
            with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
                code = main(list(args))
            if code != 0:
                raise RuntimeError(f"thermocal {' '.join(args)}: exit {code}: {err.getvalue()}")
            return out.getvalue()

        figures: dict[str, str] = {}
        with contextlib.chdir(here):
            for scenario in SCENARIOS:
                for report in scenario(run, here):
                    for name, uri in IMG.findall(report.read_text(encoding="utf-8")):
                        figures.setdefault(name, uri)  # the first report that draws it
        return figures


_FIGURES: dict[str, str] = {}


def figures() -> dict[str, str]:
    """The figures of this build, drawn once."""
    if not _FIGURES:
        _FIGURES.update(draw_figures())
    return _FIGURES


class ThermocalFigure(SphinxDirective):
    """``.. thermocal-figure:: ID`` with its caption as content."""

    required_arguments = 1
    has_content = True

    def run(self) -> list[nodes.Node]:
        name = self.arguments[0]
        drawn = figures()
        if name not in drawn:
            raise self.error(
                f"thermocal-figure: no report draws {name!r} (drawn: {', '.join(sorted(drawn))})"
            )
        figure = nodes.figure(ids=[f"gallery-{name}"], classes=["thermocal-gallery"])
        figure += nodes.image(uri=drawn[name], alt=name, candidates={"?": drawn[name]})
        legend = nodes.legend()
        self.state.nested_parse(self.content, self.content_offset, legend)
        figure += nodes.caption("", "", nodes.literal(name, name))
        figure += legend
        return [figure]


def setup(app: Sphinx) -> dict[str, Any]:
    app.add_directive("thermocal-figure", ThermocalFigure)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
