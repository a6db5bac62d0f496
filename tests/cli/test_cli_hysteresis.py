"""Thermal hysteresis through the command line: ``simulate thermal-lag``, ``fit --model hyst
--legs heating``, ``validate`` reporting each leg, ``inspect`` listing them, ``export-c``;
the refusals (exit 2, one ``error:`` line) and the isothermal record."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main
from thermocal.recording import Recording
from thermocal.simulate import SCENARIOS
from thermocal.writers import write_recording

NOISE = 0.5  # °/h, the scenario's white noise


def _run(capsys: pytest.CaptureFixture[str], args: list[str]) -> tuple[int, str, str]:
    code = main(args)
    out = capsys.readouterr()
    return code, out.out, out.err


@pytest.fixture(scope="module")
def sweep(tmp_path_factory: pytest.TempPathFactory) -> Path:
    d = tmp_path_factory.mktemp("lag")
    rec, _ = SCENARIOS["thermal-lag"](3, quant_c=0.0625)[0]
    path = d / "sweep.csv"
    write_recording(rec, path)
    return path


def _fit(capsys, sweep: Path, out: Path, *extra: str) -> dict:
    code, so, se = _run(capsys, ["fit", str(sweep), "--signal", "gyro", "--temps", "T1",
                                 "-o", str(out), "--json", *extra])  # fmt: skip
    assert code == 0, se
    return json.loads(so)


def test_fit_on_heating_validate_reports_each_leg(capsys, sweep: Path, tmp_path: Path) -> None:
    digest = hashlib.sha256(sweep.read_bytes()).hexdigest()
    hyst = _fit(capsys, sweep, tmp_path / "h.json", "--model", "hyst", "--order", "2",
                "--legs", "heating")  # fmt: skip
    poly = _fit(capsys, sweep, tmp_path / "p.json", "--model", "poly", "--order", "3",
                "--legs", "heating")  # fmt: skip
    assert hyst["n_samples"] == poly["n_samples"] == pytest.approx(2400, abs=10)
    out = {}
    for name in ("h", "p"):
        code, so, se = _run(capsys, ["validate", str(tmp_path / f"{name}.json"), str(sweep),
                                     "--json"])  # fmt: skip
        assert code == 0, se
        out[name] = json.loads(so)["legs"]
    h, p = out["h"], out["p"]
    assert [g["direction"] for g in h["legs"]] == ["heating", "cooling"]
    cool_h = next(g for g in h["legs"] if g["direction"] == "cooling")
    cool_p = next(g for g in p["legs"] if g["direction"] == "cooling")
    assert cool_h["rms"] < 1.3 * NOISE < 10 * NOISE < cool_p["rms"]
    assert h["disagree"] is False and p["disagree"] is True
    assert h["before"]["disagree"] is True  # the raw output's hysteresis
    assert p["mean_difference"] == pytest.approx(-10.5, abs=1.0)  # 2 °/h/°C × 5 °C lag
    assert abs(p["t_statistic"]) > p["t_critical"]
    assert hashlib.sha256(sweep.read_bytes()).hexdigest() == digest  # input untouched
    code, so, _ = _run(capsys, ["validate", str(tmp_path / "p.json"), str(sweep), "--legs"])
    assert "heating vs cooling: DISAGREE beyond the noise" in so
    assert "legs: 1 heating and 1 cooling legs" in so
    code, so, _ = _run(capsys, ["validate", str(tmp_path / "p.json"), str(sweep)])
    assert "heating vs cooling" not in so  # the text tables with --legs only


def test_inspect_lists_the_legs(capsys, sweep: Path) -> None:
    code, so, _ = _run(capsys, ["inspect", str(sweep), "--json"])
    assert code == 0
    legs = json.loads(so)["legs"]["T1"]
    assert (legs["n_heating"], legs["n_cooling"]) == (1, 1)
    assert legs["legs"][0]["start_s"] == pytest.approx(1800.0, abs=8.0)
    code, so, _ = _run(capsys, ["inspect", str(sweep)])
    assert "temperature 'T1': 1 heating and 1 cooling legs: heating 18" in so


def _cooling_only(path: Path) -> Path:
    t = np.arange(0.0, 4000.0)
    temp = np.interp(t, [0, 500, 3000, 4000], [60, 60, 20, 20])
    rng = np.random.default_rng(2)
    rec = Recording.from_arrays(
        t, {"gyro": 0.1 * temp + rng.standard_normal(t.size)}, {"T1": temp}, signal_unit="deg/h"
    )
    write_recording(rec, path)
    return path


def test_legs_heating_on_a_cooling_record_is_one_error_line(capsys, tmp_path: Path) -> None:
    f = _cooling_only(tmp_path / "cool.csv")
    code, _, se = _run(capsys, ["fit", str(f), "--model", "hyst", "--signal", "gyro",
                                 "--legs", "heating", "-o", str(tmp_path / "m.json")])  # fmt: skip
    assert code == 2
    lines = [ln for ln in se.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: no heating leg in ")
    assert "--legs" in lines[0]
    assert not (tmp_path / "m.json").exists()
    code, _, se = _run(capsys, ["fit", str(f), "--model", "poly", "--signal", "gyro",
                                "--legs", "sideways", "-o", str(tmp_path / "m.json")])  # fmt: skip
    assert code == 2 and se.count("error:") == 1 and "--legs" in se


def test_an_isothermal_record_validates_and_says_it_has_no_leg(capsys, tmp_path: Path) -> None:
    f = _cooling_only(tmp_path / "cool.csv")
    code, _, se = _run(capsys, ["fit", str(f), "--model", "poly", "--order", "1", "--signal",
                                "gyro", "-o", str(tmp_path / "m.json")])  # fmt: skip
    assert code == 0, se
    t = np.arange(0.0, 3600.0)
    rec = Recording.from_arrays(t, {"gyro": np.random.default_rng(1).standard_normal(t.size)},
                                {"T1": np.full(t.size, 40.0)}, signal_unit="deg/h")  # fmt: skip
    iso = tmp_path / "iso.csv"
    write_recording(rec, iso)
    code, so, se = _run(capsys, ["validate", str(tmp_path / "m.json"), str(iso), "--json"])
    assert code == 0, se
    legs = json.loads(so)["legs"]
    assert legs["legs"] == [] and legs["disagree"] is None
    assert legs["summary"].startswith("no heating or cooling leg")
    assert legs["reason"] == "no heating leg"
    code, so, _ = _run(capsys, ["inspect", str(iso), "--json"])
    assert json.loads(so)["legs"]["T1"]["summary"].startswith("no heating or cooling leg")


def test_validate_legs_prints_every_channel_of_a_calibration(capsys, tmp_path: Path) -> None:
    """Two channels with opposite hysteresis (the second the first negated, its own noise):
    each channel's legs table and heating-vs-cooling line in the text, the same figures as
    the JSON's."""
    import pandas as pd

    rec, _ = SCENARIOS["thermal-lag"](3, quant_c=0.0625)[0]
    write_recording(rec, tmp_path / "one.csv")
    df = pd.read_csv(tmp_path / "one.csv")
    df["gyro_b"] = -df["gyro"] + np.random.default_rng(9).normal(0.0, NOISE, len(df))
    df.to_csv(tmp_path / "two.csv", index=False)
    code, _, se = _run(capsys, ["fit", str(tmp_path / "two.csv"), "--signal", "gyro,gyro_b",
                                "--temps", "T1", "--signal-unit", "deg/h", "--model", "poly",
                                "--order", "3", "--legs", "heating",
                                "-o", str(tmp_path / "cal.json")])  # fmt: skip
    assert code == 0, se
    args = ["validate", str(tmp_path / "cal.json"), str(tmp_path / "two.csv")]
    code, so, se = _run(capsys, [*args, "--json"])
    assert code == 0, se
    legs = {name: ch["legs"] for name, ch in json.loads(so)["channels"].items()}
    # the poly's heating-leg fit leaves −10.5 °/h (2 °/h/°C × 5 °C of lag) on the first, +10.5
    assert legs["gyro"]["mean_difference"] == pytest.approx(-10.5, abs=1.0)
    assert legs["gyro_b"]["mean_difference"] == pytest.approx(10.5, abs=1.0)
    code, so, se = _run(capsys, [*args, "--legs"])
    assert code == 0, se
    for name in ("gyro", "gyro_b"):
        assert f"{name}: legs: 1 heating and 1 cooling legs" in so
        assert f"{name}: legs after compensation" in so
        after = next(ln for ln in so.splitlines() if ln.startswith(f"{name}: after: "))
        assert "DISAGREE beyond the noise" in after
        assert f"mean difference {legs[name]['mean_difference']:.4g} deg/h" in after
    code, so, _ = _run(capsys, args)
    assert "heating vs cooling" not in so
