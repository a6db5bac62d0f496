"""Two more tutorials run as written (the runner of ``test_tutorials.py``): the production
batch (``thermocal fleet`` over units made by ``thermocal simulate``) and the
flight-controller log → PX4 and ArduPilot parameters.  Besides printing what the page shows,
each unit's fleet coefficients equal an independent least-squares cubic (``numpy.polyfit``) of
its file and follow its simulated truth; the firmware parameters, applied through PX4's and
ArduPilot's own correction formulas written out here, remove the log's simulated bias.

A ```` ```toml ```` block whose first line is ``# file: NAME`` is written to NAME before the
blocks that follow run; a ``$ thermocal …`` line may exit 4 where the page says so (a batch
with a failed unit): the exit statuses are returned and asserted."""

from __future__ import annotations

import contextlib
import importlib.util
import io
import json
import math
import shlex
from pathlib import Path
from types import ModuleType

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main
from tutorial_pages import BLOCK, ROOT, TUTORIALS, _numbers, fresh_cli

Page = list[tuple[str, str, list[int]]]


def _lines(text: str) -> list[str]:
    """The text's non-blank lines without the blanks around them: rich pads a table's
    title to the table's width with spaces on both sides (older rich, the floor's, also
    on the right), which a page does not show."""
    return [ln.strip() for ln in text.splitlines() if ln.strip()]


def _run_console(body: str) -> tuple[str, list[int]]:
    """What the block's ``$ thermocal …`` lines print on stdout, and their exit statuses."""
    out = io.StringIO()
    codes: list[int] = []
    for line in body.splitlines():
        assert line.startswith("$ thermocal "), line
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):
            codes.append(main(shlex.split(line[len("$ thermocal ") :])))
    return out.getvalue(), codes


def _run_page(page: Path, here: Path) -> Page:
    """(printed, shown, exit statuses) per executable block, in order; the scratch folder's
    absolute path printed as ``.``."""
    blocks = [(m.group(1), m.group(2)) for m in BLOCK.finditer(page.read_text(encoding="utf-8"))]
    done: Page = []
    for i, (lang, body) in enumerate(blocks):
        if lang == "toml":
            first, _, rest = body.partition("\n")
            assert first.startswith("# file: "), first
            (here / first[len("# file: ") :]).write_text(rest, encoding="utf-8")
        elif lang in ("console", "python"):
            codes: list[int] = []
            if lang == "python":
                buf = io.StringIO()
                with contextlib.redirect_stdout(buf):
                    exec(compile(body, page.name, "exec"), {})
                printed = buf.getvalue()
            else:
                printed, codes = _run_console(body)
            shown = next(b for la, b in blocks[i + 1 :] if la == "text")
            done.append((printed.replace(str(here), "."), shown, codes))
    return done


def _in_scratch(tmp: Path, name: str) -> Page:
    with pytest.MonkeyPatch.context() as mp:
        fresh_cli(mp)
        mp.chdir(tmp)
        return _run_page(TUTORIALS / name, tmp)


@pytest.fixture(scope="module")
def batch_page(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Page]:
    tmp = tmp_path_factory.mktemp("batch")
    return tmp, _in_scratch(tmp, "production-batch.md")


def test_batch_tutorial_prints_what_the_page_shows(batch_page: tuple[Path, Page]) -> None:
    _, page = batch_page
    assert [codes for _p, _s, codes in page] == [[0] * 4, [4], [0, 0], []]
    for printed, shown, _codes in page:
        assert _numbers(printed) == _numbers(shown)
        assert _lines(printed) == _lines(shown)


def test_batch_coefficients_are_a_least_squares_cubic_of_each_unit(
    batch_page: tuple[Path, Page],
) -> None:
    """numpy's polyfit of the same file gives the fleet's coefficients; the model follows the
    unit's noiseless output (``truth_rate``) to within the cubic's misfit of the simulated
    piecewise-linear bias — which is itself computed here by fitting the truth."""
    tmp, _ = batch_page
    for k in range(1, 6):
        uid = f"SN000{k}"
        rec = json.loads((tmp / "batch-out" / "units" / uid / "unit.json").read_text())
        assert rec["status"] == "ok" and rec["pass"] is True
        c = rec["channels"]["gyro"]["coefficients"]
        mine = np.array([c["T1^3"], c["T1^2"], c["T1"], c["const"]])
        run = pd.read_csv(tmp / f"{uid}.csv")
        np.testing.assert_allclose(mine, np.polyfit(run["T1"], run["gyro"], 3), rtol=1e-6)
        truth = json.loads((tmp / f"{uid}_truth.json").read_text())["files"][0]
        assert truth["seed"] == k
        model = np.polyval(mine, run["T1"])
        err = float(np.sqrt(np.mean((model - run["truth_rate"]) ** 2)))
        best = np.polyval(np.polyfit(run["T1"], run["truth_rate"], 3), run["T1"])
        misfit = float(np.sqrt(np.mean((best - run["truth_rate"]) ** 2)))
        # the noise (0.18 °/√h white, averaged over 10 s) adds little to the misfit
        assert misfit < err < misfit + 0.03, (uid, err, misfit)
        # the level: earth rate + constant bias + this unit's turn-on bias (σ 0.05 °/h)
        level = truth["input"] + truth["bias_constant"] + truth["turn_on_offset"]
        true_mean = float(np.mean(level + run["truth_bias"]))
        assert float(np.mean(model)) == pytest.approx(true_mean, abs=0.01), uid
        assert rec["channels"]["gyro"]["rms_residual"] < 0.45


def test_every_page_here_is_in_the_toctree() -> None:
    index = (ROOT / "docs" / "index.md").read_text(encoding="utf-8")
    for name in ("production-batch", "fc-params"):
        assert f"tutorials/{name}\n" in index
        assert (TUTORIALS / f"{name}.md").is_file()


DATA = TUTORIALS / "data"


def _make_fc_logs() -> ModuleType:
    spec = importlib.util.spec_from_file_location("make_fc_logs", DATA / "make_fc_logs.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def fc_page(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Page]:
    tmp = tmp_path_factory.mktemp("fc")
    (tmp / "docs").symlink_to(ROOT / "docs", target_is_directory=True)
    return tmp, _in_scratch(tmp, "fc-params.md")


def test_the_shipped_logs_are_what_their_script_makes() -> None:
    make = _make_fc_logs()
    assert (DATA / "sweep.ulg").read_bytes() == make.ulog()
    assert (DATA / "sweep.bin").read_bytes() == make.dataflash()
    assert (DATA / "heated.ulg").read_bytes() == make.heated()
    assert sum(p.stat().st_size for p in DATA.iterdir()) < 500_000


def test_fc_tutorial_prints_what_the_page_shows(fc_page: tuple[Path, Page]) -> None:
    _, page = fc_page
    # the fifth: heated; the sixth: the thermometers' python block
    assert [codes for _p, _s, codes in page] == [[0], [], [0], [0], [0], []]
    for printed, shown, _codes in page:
        assert _numbers(printed) == _numbers(shown)
        assert _lines(printed) == _lines(shown)


def test_fc_holdout_is_the_noise_of_the_bins(fc_page: tuple[Path, Page]) -> None:
    """The gyro's hold-out rms per axis is the noise of a bin's median: 0.001 rad/s per sample
    (make_fc_logs.py) over 3000/121 samples a bin, ×1.25 (a median's efficiency) ≈ 52 °/h."""
    _, page = fc_page
    expected = 0.001 * 180 / math.pi * 3600 / math.sqrt(3000 / 121) * 1.25
    for printed in (page[0][0], page[2][0]):
        row = next(ln for ln in printed.splitlines() if "deg/h" in ln and "│" in ln)
        values = [float(v) for v in row.split("│")[-2].split("deg/h")[0].split("/")]
        assert len(values) == 3
        for v in values:
            assert 0.8 * expected < v < 1.25 * expected, (v, expected)


def _px4_params(path: Path) -> dict[str, float]:
    out = {}
    for line in path.read_text().splitlines():
        if not line.startswith("#"):
            _v, _c, name, value, _t = line.split("\t")
            out[name] = float(value)
    return out


def _ardupilot_params(path: Path) -> dict[str, float]:
    rows = (line.split() for line in path.read_text().splitlines() if not line.startswith("#"))
    return {name: float(value) for name, value in rows}


NOISE = {"G": 0.001, "A": 0.02, "GYR": 0.001, "ACC": 0.02}
"""White noise per sample of make_fc_logs.py [rad/s, m/s²]."""


def _misfit(correction: np.ndarray, truth: np.ndarray, kind: str) -> float:
    """rms of correction − truth (levels aside) over what the noise allows a cubic fitted
    on N samples: σ·√(4/N), ×1.25 for a fit of bin medians (the medians' efficiency)."""
    err = (correction - correction.mean()) - (truth - truth.mean())
    return math.sqrt(float(np.mean(err**2))) / (1.25 * NOISE[kind] * math.sqrt(4 / truth.size))


def test_px4_parameters_remove_the_simulated_bias(fc_page: tuple[Path, Page]) -> None:
    """PX4's correction (TemperatureCompensation.cpp: X0 + X1·dT + X2·dT² + X3·dT³,
    dT = clamp(T, TMIN, TMAX) − TREF, written out here) on the log's true temperatures
    follows every axis's true bias to within 3× what the noise allows a cubic (levels aside);
    the gyro's X0 is its true bias at TREF (to 1e-4 rad/s, ≈ 2σ of a 3000-sample cubic); the
    accelerometer's X0 is 0 (relative offsets)."""
    tmp, _ = fc_page
    p = _px4_params(tmp / "px4" / "px4.params")
    _t, temp, gyro, accel = _make_fc_logs().truth()
    temp = temp.astype(np.float32).astype(np.float64)  # the log's float32
    assert p["TC_G0_ID"] == 2293768 and p["TC_A0_ID"] == 2293776
    for kind, truth in (("G", gyro), ("A", accel)):
        assert p[f"TC_{kind}0_TMIN"] == pytest.approx(-9.875, abs=0.01)  # the lowest bin
        assert p[f"TC_{kind}0_TMAX"] == pytest.approx(50.0, abs=1e-6)
        dt = np.clip(temp, p[f"TC_{kind}0_TMIN"], p[f"TC_{kind}0_TMAX"]) - p[f"TC_{kind}0_TREF"]
        for i in range(3):
            x = [p[f"TC_{kind}0_X{k}_{i}"] for k in range(4)]
            offset = x[0] + x[1] * dt + x[2] * dt**2 + x[3] * dt**3
            assert _misfit(offset, truth[:, i], kind) < 3.0, (kind, i)
    tref = p["TC_G0_TREF"]
    u = (tref - 20.0) / 30.0
    true_at_tref = [0.002 + 0.004 * u - 0.001 * u**2 + 0.0005 * u**3, -0.001 + 0.002 * u,
                    0.003 * u**2]  # fmt: skip
    for i in range(3):
        assert p[f"TC_G0_X0_{i}"] == pytest.approx(true_at_tref[i], abs=1e-4)
        assert p[f"TC_A0_X0_{i}"] == 0.0


def test_ardupilot_parameters_are_px4s_cubic_about_35_c(fc_page: tuple[Path, Page]) -> None:
    """ArduPilot's correction (AP_InertialSensor_tempcal.cpp: poly(clamp(T) − 35) with
    poly(t) = (c1 + (c2 + c3·t)·t)·t·1e-6, relative to the calibration temperature) equals
    PX4's cubic minus its value at 35 °C, at every temperature (the same fit: one
    re-expansion), follows the true bias as closely, and the DataFlash log's file equals
    export-params' from the PX4 calibration."""
    tmp, _ = fc_page
    ap = _ardupilot_params(tmp / "ardupilot" / "ardupilot.parm")
    assert ap == _ardupilot_params(tmp / "px4" / "ardupilot.parm")
    p = _px4_params(tmp / "px4" / "px4.params")
    _t, temp, gyro, accel = _make_fc_logs().truth()
    grid = np.linspace(-9.0, 49.0, 59)
    assert ap["INS_TCAL1_ENABLE"] == 1
    for tag, kind, truth in (("GYR", "G", gyro), ("ACC", "A", accel)):
        for i, axis in enumerate("XYZ"):
            c = [ap[f"INS_TCAL1_{tag}{k}_{axis}"] for k in (1, 2, 3)]
            x = [p[f"TC_{kind}0_X{k}_{i}"] for k in range(4)]
            tref = p[f"TC_{kind}0_TREF"]

            def poly(t: np.ndarray, c: list[float] = c) -> np.ndarray:
                """ArduPilot's: (c1 + (c2 + c3·t)·t)·t·1e-6."""
                return np.asarray((c[0] + (c[1] + c[2] * t) * t) * t * 1e-6)

            def px4(temp_c: np.ndarray, x: list[float] = x, tref: float = tref) -> np.ndarray:
                """PX4's: X0 + X1·dT + X2·dT² + X3·dT³, dT = T − TREF."""
                dt = temp_c - tref
                return np.asarray(x[0] + x[1] * dt + x[2] * dt**2 + x[3] * dt**3)

            np.testing.assert_allclose(
                poly(grid - 35.0), px4(grid) - px4(np.array(35.0)), atol=1e-9
            )
            tc = np.clip(temp, ap["INS_TCAL1_TMIN"], ap["INS_TCAL1_TMAX"])
            assert _misfit(poly(tc - 35.0), truth[:, i], tag) < 3.0, (tag, axis)
