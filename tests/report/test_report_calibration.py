"""``thermocal report`` for a calibration (issue 15): one document for every channel,
each channel's figures in its data column's own unit, checked against numbers computed
here with numpy from the file (not by the code under test), and rendered in Chromium."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest

from report_checks import (
    check_number,
    check_rendered,
    run_chromium,
    skip_without_chromium,
    tagged_numbers,
)
from thermocal.cli import main
from thermocal.simulate import SCENARIOS
from thermocal.writers import write_recording

NAMES = ["gx", "gy", "gz", "ax", "ay", "az"]
RAD_PER_DEG = np.pi / 180.0


def _run(args: list[str]) -> tuple[int, str]:
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        status = main(args)
    return status, buf.getvalue()


@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """The IMU scenario as another tool would write it: a CSV with gy in rad/s (not the
    simulator's deg/s, nor the unit the calibration was fitted in), units in a sidecar."""
    d = tmp_path_factory.mktemp("calrep")
    ((mod, _t),) = SCENARIOS["mems-imu"](5, rate_hz=0.2)
    ((val, _),) = SCENARIOS["mems-imu"](5, run="validation", rate_hz=0.2)
    write_recording(mod, d / "mod.parquet")
    frame = pd.DataFrame({"time (s)": val.time_s, "T_die (degC)": val.column("T_die"),
                          "T_chamber (degC)": val.column("T_chamber")})  # fmt: skip
    for n in NAMES:
        unit = val.units[n]
        x = val.column(n)
        if n == "gy":
            x, unit = x * RAD_PER_DEG, "rad/s"
        frame[f"{n} [{unit}]"] = x
    cal = d / "cal.json"
    sig = ",".join(NAMES)
    status, text = _run(["fit", str(d / "mod.parquet"), "--model", "poly", "--order", "3",
                         "--signal", sig, "--temps", "T_die", "-o", str(cal)])  # fmt: skip
    assert status == 0, text
    # a calibration reads its channels by the fitted column names: the units go to a sidecar
    renamed = d / "val-named.csv"
    frame.rename(columns={c: c.split(" ")[0] for c in frame.columns}).to_csv(renamed, index=False)
    (d / "val-named.csv.meta.json").write_text(json.dumps({
        "time": "time", "time_unit": "s",
        "units": {**{n: ("rad/s" if n == "gy" else val.units[n]) for n in NAMES},
                  "T_die": "degC", "T_chamber": "degC"},
    }))  # fmt: skip
    status, text = _run(["validate", str(cal), str(renamed), "--modeling", str(d / "mod.parquet"),
                         "--ambient", "T_chamber", "--json"])  # fmt: skip
    assert status == 0, text
    (d / "v.json").write_text(text)
    return {"dir": d, "cal": cal, "val": renamed, "frame": frame, "v": json.loads(text)}


def _stability(x: np.ndarray, tau0: float, averaging_s: float) -> float:
    """SPEC §1 bias stability, written out here: std (n − 1) of consecutive averages."""
    m = round(averaging_s / tau0)
    k = x.size // m
    return float(np.std(x[: k * m].reshape(k, m).mean(axis=1), ddof=1))


def test_calibration_report_every_channel_in_its_own_unit(
    files: dict[str, Any], tmp_path: Path
) -> None:
    d = files["dir"]
    out = tmp_path / "r.html"
    status, text = _run(["report", "--model", str(files["cal"]), "--recording", str(files["val"]),
                         "--validation", str(d / "v.json"), "--modeling", str(d / "mod.parquet"),
                         "-o", str(out), "--average", "100"])  # fmt: skip
    assert status == 0, text
    html = out.read_text()
    tags = tagged_numbers(html)
    frame = pd.read_csv(files["val"])
    tau0 = float(np.median(np.diff(frame["time"])))
    for n in NAMES:
        # before compensation: the raw column in its own unit (gy in rad/s)
        want = _stability(frame[n].to_numpy(), tau0, 100.0)
        check_number(tags, f"channels.{n}.bias_stability_before", want, rel=1e-9)
        for key in ("r", "rms_before", "rms_after"):
            check_number(tags, f"channels.{n}.validation.{key}",
                         files["v"]["channels"][n][key])  # fmt: skip
        # issue 38: the bias instability is read at the curve's minimum, never "—"
        for when in ("before", "after"):
            assert tags[f"channels.{n}.bias_instability_{when}"][1] != "—", (n, when)
    # the gy figures are in rad/s: its validation rms is the deg/s one times π/180
    assert files["v"]["channels"]["gy"]["unit"] == "rad/s"
    assert '<tr data-channel="gy"><td><a href="#ch-gy">gy</a> <span class="unit">[rad/s]' in html
    # one verdict badge per channel (the adequacy tables carry badges of their own)
    assert html.count('<td><span class="badge pass">improved</span></td>') == 6


def test_calibration_report_without_validation_states_no_verdict(
    files: dict[str, Any], tmp_path: Path
) -> None:
    out = tmp_path / "r.html"
    status, text = _run(["report", "--model", str(files["cal"]), "--recording", str(files["val"]),
                         "--signal", "gx,az", "-o", str(out)])  # fmt: skip
    assert status == 0, text
    html = out.read_text()
    assert "No validation result was given" in html
    # no verdict badge (the adequacy tables carry badges of their own)
    assert 'badge pass">improved' not in html and 'badge fail">NOT' not in html
    rows = [n for n in NAMES if f'data-channel="{n}"' in html]
    assert rows == ["gx", "az"]


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--signal", "gx,nope"], "no channel 'nope'"),
        (["--model", "SECOND"], "only --model"),
    ],
)
def test_calibration_report_refuses(
    files: dict[str, Any], tmp_path: Path, extra: list[str], message: str,
    capsys: pytest.CaptureFixture[str],
) -> None:  # fmt: skip
    extra = [str(files["cal"]) if e == "SECOND" else e for e in extra]
    status = main(["report", "--model", str(files["cal"]), "--recording", str(files["val"]),
                   "-o", str(tmp_path / "r.html"), *extra])  # fmt: skip
    assert status == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "r.html").exists()


def test_calibration_report_renders_in_headless_chromium(
    files: dict[str, Any], tmp_path: Path
) -> None:
    skip_without_chromium()
    out = tmp_path / "r.html"
    status, text = _run(["report", "--model", str(files["cal"]), "--recording", str(files["val"]),
                         "--validation", str(files["dir"] / "v.json"), "-o", str(out)])  # fmt: skip
    assert status == 0, text
    check_rendered(run_chromium(out, tmp_path), n_figures_min=2)


def test_calibration_report_absolute_error_gaps_and_warnings_once(
    files: dict[str, Any], tmp_path: Path
) -> None:
    """Issue 38: the multi-channel report showed only the scatter about the mean where the
    validation has the error against the reference falling; called a record of mostly gaps
    "N h, n samples every τ0 s"; and printed every warning twice.  Figures computed here."""
    d, v = files["dir"], json.loads(json.dumps(files["v"]))
    shared = "the validation run was recorded on another day (a test warning)"
    for n in NAMES:
        v["channels"][n]["warnings"] = [*v["channels"][n].get("warnings", []), shared]
    (tmp_path / "v.json").write_text(json.dumps(v))
    frame = pd.read_csv(files["val"])
    keep = (np.arange(len(frame)) // 50) % 10 == 0  # blocks of 50 samples, 9 of 10 dropped
    frame[keep].to_csv(tmp_path / "gapped.csv", index=False)
    (tmp_path / "gapped.csv.meta.json").write_text((d / "val-named.csv.meta.json").read_text())
    out = tmp_path / "r.html"
    status, text = _run(["report", "--model", str(files["cal"]), "--recording",
                         str(tmp_path / "gapped.csv"), "--validation", str(tmp_path / "v.json"),
                         "-o", str(out)])  # fmt: skip
    assert status == 0, text
    html = out.read_text()
    tags = tagged_numbers(html)
    for n in NAMES:
        b, a = (v["channels"][n][f"rms_about_zero_{w}"] for w in ("before", "after"))
        check_number(tags, f"channels.{n}.validation.rms_about_zero_before", b)
        check_number(tags, f"channels.{n}.validation.rms_about_zero_after", a)
        check_number(tags, f"channels.{n}.validation.rms_about_zero_improvement_pct",
                     100.0 * (1.0 - abs(a) / abs(b)), rel=1e-12)  # fmt: skip
    t = frame["time"].to_numpy()[keep]
    tau0 = float(np.median(np.diff(frame["time"])))
    steps = np.diff(t)
    gap_s = float(np.sum(steps[steps > 1.5 * tau0] - tau0))
    check_number(tags, "coverage.gap_h", gap_s / 3600.0, rel=1e-12)
    check_number(tags, "coverage.covered_h", (t[-1] - t[0] - gap_s) / 3600.0, rel=1e-12)
    check_number(tags, "coverage.gap_pct", 100.0 * gap_s / (t[-1] - t[0]), rel=1e-12)
    assert f"{int(np.count_nonzero(steps > 1.5 * tau0))} gap(s)" in html
    assert html.count(shared) == 1 and "(every channel)" in html
