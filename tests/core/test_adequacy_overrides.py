"""Issue 39: the adequacy survivors of the last wave — "any override passes every adequacy
test", "n = p made overridable", "the worst stillness taken as the best".

Through the command line (``thermocal.cli.main``), on recordings simulated here with a known
truth: the sweep's span and the soak temperatures are what the test wrote, the moving share
is the length of the turns the test added over the record's length, n and p are the rows
written and the polynomial's order + 1.  Every input is hashed before and after.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main

RATE_HZ = 10.0
DURATION_S = 600.0
SIG, TEMP = "gx [deg/s]", "T1 [degC]"


def _digest(*paths: Path) -> list[str]:
    return [hashlib.sha256(p.read_bytes()).hexdigest() for p in paths]


def _record(
    path: Path, temp: np.ndarray, turns: tuple[tuple[float, float], ...] = (), seed: int = 3
) -> Path:
    """A still gyro (0.1 deg/s + 0.002 deg/s/°C, white noise 0.001 deg/s) at 10 Hz over
    600 s following ``temp``; each ``(start, seconds)`` of ``turns`` adds a turn at 5 deg/s
    (16× the 0.3 deg/s motion floor)."""
    rng = np.random.default_rng(seed)
    t = np.arange(temp.size) / RATE_HZ
    gx = 0.1 + 0.002 * (temp - 25.0) + rng.normal(0.0, 0.001, t.size)
    for a, d in turns:
        gx[(t >= a) & (t < a + d)] += 5.0
    pd.DataFrame({"time (s)": t, SIG: gx, TEMP: temp}).to_csv(path, index=False)
    return path


def _sweep(lo: float, hi: float) -> np.ndarray:
    n = int(DURATION_S * RATE_HZ)
    return lo + (hi - lo) * np.arange(n) / (n - 1)


def _fit(capsys: pytest.CaptureFixture[str], files: list[Path], out: Path, order: int,
         *extra: str) -> tuple[int, list[str], list[str]]:  # fmt: skip
    rc = main(["fit", *map(str, files), "--model", "poly", "--order", str(order), "--signal",
               SIG, "--temps", TEMP, "-o", str(out), *extra])  # fmt: skip
    err = capsys.readouterr().err.strip().splitlines()
    return rc, [ln for ln in err if ln.startswith("error:")], err


@pytest.mark.parametrize(
    ("data", "given", "needed"), [("narrow", "--allow-motion", "--allow-narrow"),
                                  ("moving", "--allow-narrow", "--allow-motion")],
)  # fmt: skip
def test_one_override_does_not_pass_the_other_test(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], data: str, given: str, needed: str
) -> None:
    """A 2 °C sweep for a line (5 °C needed) is not allowed by ``--allow-motion``; a record
    moving 5 % of the time (three 10-s turns in 600 s; 2 % allowed) is not allowed by
    ``--allow-narrow``.  Each is refused naming the override that would allow it; with
    that one the fit is written with a warning."""
    if data == "narrow":
        temp = _sweep(25.0, 27.0)
        f = _record(tmp_path / "narrow.csv", temp)
        words = f"spans {np.ptp(temp):g} °C"  # 2 °C, from the sweep written
    else:
        f = _record(tmp_path / "moving.csv", _sweep(20.0, 40.0),
                    turns=((100.0, 10.0), (300.0, 10.0), (500.0, 10.0)))  # fmt: skip
        words = f"moved during {100 * 30.0 / DURATION_S:g} % of the record"  # 5 %
    before = _digest(f)
    out = tmp_path / "m.json"
    rc, errors, _err = _fit(capsys, [f], out, 1, given)
    assert rc == 2 and len(errors) == 1, errors
    assert words in errors[0] and f"(to fit anyway, knowingly: {needed})" in errors[0], errors
    assert not out.exists()
    rc, errors, err = _fit(capsys, [f], out, 1, needed)
    assert rc == 0 and errors == [], err
    assert any(f"fitted anyway ({needed})" in ln for ln in err), err
    ad = json.loads(out.read_text())["adequacy"]
    assert ad["verdict"] == "overridden" and ad["overrides"] == [needed]
    assert _digest(f) == before


def test_as_many_samples_as_coefficients_is_refused_whatever_the_override(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """6 rows over 30 °C and a quintic (order 5: 6 coefficients): the polynomial passes
    through every sample; refused with --allow-narrow, and no override is offered."""
    temp = np.array([10.0, 16.0, 22.0, 28.0, 34.0, 40.0])
    t = np.arange(temp.size) * 10.0
    f = tmp_path / "six.csv"
    pd.DataFrame({"time (s)": t, SIG: 0.1 + 0.002 * (temp - 25.0), TEMP: temp}).to_csv(
        f, index=False
    )
    order = 5
    p = np.polynomial.polynomial.polyvander(temp, order).shape[1]  # coefficients: 6
    assert p == temp.size
    before = _digest(f)
    out = tmp_path / "m.json"
    rc, errors, _err = _fit(capsys, [f], out, order, "--allow-narrow", "--allow-motion")
    assert rc == 2 and len(errors) == 1, errors
    assert f"{temp.size} samples for {p} coefficients: the fit would pass through" in errors[0]
    assert "to fit anyway" not in errors[0] and not out.exists()
    assert _digest(f) == before


def test_fewer_soak_temperatures_than_coefficients_is_refused_whatever_the_override(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Two soaks (25 and 45 °C, 300 s each) cannot determine a quadratic (3 coefficients):
    refused with --allow-narrow, no override offered; a line through them is fitted."""
    n = int(DURATION_S * RATE_HZ)
    rng = np.random.default_rng(5)
    temp = np.where(np.arange(n) < n // 2, 25.0, 45.0) + rng.normal(0.0, 0.01, n)
    f = _record(tmp_path / "soaks.csv", temp)
    soaks = np.unique(np.round(temp))  # 25 and 45
    before = _digest(f)
    out = tmp_path / "m.json"
    rc, errors, _err = _fit(capsys, [f], out, 2, "--allow-narrow")
    assert rc == 2 and len(errors) == 1, errors
    assert f"holds {soaks.size} distinct temperature(s)" in errors[0]
    assert "needs ≥ 3" in errors[0] and "to fit anyway" not in errors[0]
    assert not out.exists()
    rc, errors, err = _fit(capsys, [f], out, 1)
    assert rc == 0 and errors == [], err  # 2 soaks for a line: a warning, not a refusal
    assert _digest(f) == before


@pytest.mark.parametrize("moving_first", [False, True])
def test_the_worst_run_decides_the_stillness(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], moving_first: bool
) -> None:
    """Two runs over 20…40 °C, one still, one moving 5 % of the time: the fit is refused
    naming the moving run, whichever comes first."""
    still = _record(tmp_path / "still.csv", _sweep(20.0, 40.0), seed=7)
    moving = _record(tmp_path / "moving.csv", _sweep(20.0, 40.0),
                     turns=((100.0, 10.0), (300.0, 10.0), (500.0, 10.0)))  # fmt: skip
    files = [moving, still] if moving_first else [still, moving]
    before = _digest(*files)
    out = tmp_path / "m.json"
    rc, errors, _err = _fit(capsys, files, out, 1)
    assert rc == 2 and len(errors) == 1, errors
    run = files.index(moving) + 1
    assert f"gx [deg/s] (run {run}): the sensor moved during 5 % of the record" in errors[0]
    assert not out.exists() and _digest(*files) == before


def test_of_two_warned_runs_the_larger_moving_share_is_recorded(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Both runs moved briefly (a warning each): 3 s and 9 s of 600 s.  The record keeps
    the worse, 9 / 600 = 1.5 % (the turns the test added), whichever run comes first."""
    short = _record(tmp_path / "a.csv", _sweep(20.0, 40.0), turns=((200.0, 3.0),), seed=8)
    long_ = _record(tmp_path / "b.csv", _sweep(20.0, 40.0), turns=((200.0, 9.0),), seed=9)
    for files in ([short, long_], [long_, short]):
        out = tmp_path / f"m-{files[0].stem}.json"
        rc, errors, err = _fit(capsys, files, out, 1)
        assert rc == 0 and errors == [], err
        tests = json.loads(out.read_text())["adequacy"]["tests"]
        (st,) = [t for t in tests if t["name"] == "stillness"]
        assert st["verdict"] == "warn"
        assert st["figure"] == pytest.approx(100.0 * 9.0 / DURATION_S, abs=0.2)
