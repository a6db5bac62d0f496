"""``thermocal fleet`` in the data's unit (issue 25 item 7): every per-channel figure of
``unit.json``, ``summary.csv``/``summary.parquet`` and ``fleet.html`` is in the unit of the
channel's column as given (°/s, rad/s, mg), not the model's internal °/h; limits are
compared in that unit, so the yield is right.

The expected figures are computed here, from the values the files hold: an ordinary
least-squares line in numpy for the fit (rms residual, coefficients), and the rms about the
mean of 10 s averages of the validation run before and after subtracting that line."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from fleet_data import CHANNELS, TEMP, Run, config_text, write_run
from thermocal.cli import main

AVERAGING = 10
"""[validate] averaging [s] = 10 samples at 1 Hz."""


def _rms_of_averages(y: np.ndarray) -> float:
    m = y[: y.size // AVERAGING * AVERAGING].reshape(-1, AVERAGING).mean(axis=1)
    return float(np.sqrt(np.mean((m - m.mean()) ** 2)))


def _expected(mod: Run, val: Run, col: str) -> dict[str, float]:
    """The figures of ``col`` in its own unit, by numpy alone."""
    T, x = mod.frame[TEMP].to_numpy(), mod.frame[col].to_numpy()
    A = np.column_stack([np.ones_like(T), T])
    coef, *_ = np.linalg.lstsq(A, x, rcond=None)
    resid = x - A @ coef
    Tv, xv = val.frame[TEMP].to_numpy(), val.frame[col].to_numpy()
    return {
        "const": float(coef[0]),
        "T1": float(coef[1]),
        "rms_residual": float(np.sqrt(np.mean(resid**2))),
        "rms_before": _rms_of_averages(xv),
        "rms_after": _rms_of_averages(xv - (coef[0] + coef[1] * Tv)),
    }


@pytest.fixture
def two_units(tmp_path: Path) -> tuple[Path, dict[str, dict[str, dict[str, float]]]]:
    """U1 (the noise of :data:`CHANNELS`) and U2 (three times as noisy), both validated;
    returns the data folder and the expected figures per unit and channel."""
    data = tmp_path / "data"
    data.mkdir()
    expected: dict[str, dict[str, dict[str, float]]] = {}
    for i, (uid, scale) in enumerate((("U1", 1.0), ("U2", 3.0))):
        mod = write_run(data / f"{uid}_mod.csv", 10 + i, noise_scale=scale)
        val = write_run(data / f"{uid}_val.csv", 20 + i, noise_scale=scale, validation=True)
        expected[uid] = {c: _expected(mod, val, c) for c in CHANNELS}
    return data, expected


UNITS = {"gx [deg/s]": "deg/s", "gy [rad/s]": "rad/s", "az [mg]": "mg"}


def _run(cfg: Path, out: Path, capsys: pytest.CaptureFixture[str]) -> tuple[int, dict]:  # type: ignore[type-arg]
    capsys.readouterr()
    code = main(["fleet", str(cfg), "-o", str(out), "--workers", "1", "--json"])
    return code, json.loads(capsys.readouterr().out)


def test_every_figure_in_the_channels_own_unit(
    two_units: tuple[Path, dict[str, dict[str, dict[str, float]]]],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """unit.json, summary.csv, summary.parquet and fleet.html against numpy's figures; the
    limits, set half-way (geometric mean) between U1's and U2's true figures in each
    channel's own unit, pass U1 and fail U2: a yield of 50 %."""
    _data, exp = two_units
    limits = "\n".join(
        f'[limits."{c}"]\n{fig}_max = {math.sqrt(exp["U1"][c][fig] * exp["U2"][c][fig])!r}'
        for c, fig in (
            ("gx [deg/s]", "rms_residual"),
            ("gy [rad/s]", "rms_after"),
            ("az [mg]", "rms_residual"),
        )
    )
    cfg = tmp_path / "batch.toml"
    units = {u: (f"data/{u}_mod.csv", f"data/{u}_val.csv") for u in ("U1", "U2")}
    cfg.write_text(config_text(units, limits=limits), encoding="utf-8")
    out = tmp_path / "out"
    code, res = _run(cfg, out, capsys)
    assert code == 0 and res["ok"] == 2 and res["passed"] == 1

    csv = pd.read_csv(out / "summary.csv").set_index("id")
    pq = pd.read_parquet(out / "summary.parquet").set_index("id")
    html = (out / "fleet.html").read_text(encoding="utf-8")
    for uid in ("U1", "U2"):
        rec = json.loads((out / "units" / uid / "unit.json").read_text(encoding="utf-8"))
        for col, unit in UNITS.items():
            e, fig = exp[uid][col], rec["channels"][col]
            assert fig["unit"] == unit
            assert fig["coefficient_units"] == {"const": unit, "T1": f"{unit}/degC"}
            assert fig["coefficients"]["const"] == pytest.approx(e["const"], rel=1e-7)
            assert fig["coefficients"]["T1"] == pytest.approx(e["T1"], rel=1e-7)
            for k in ("rms_residual", "rms_before", "rms_after"):
                assert fig[k] == pytest.approx(e[k], rel=1e-7), (uid, col, k)
                assert csv.loc[uid, f"{col}.{k}"] == pytest.approx(e[k], rel=1e-7)
                assert pq.loc[uid, f"{col}.{k}"] == pytest.approx(e[k], rel=1e-7)
            assert csv.loc[uid, f"{col}.unit"] == unit
            # the slope written (truth), within the noise of 3000 samples over 70 °C
            _bias, slope, sigma = CHANNELS[col]
            se = 3 * sigma / (float(np.std(np.linspace(-10, 60, 3000))) * math.sqrt(3000))
            assert fig["coefficients"]["T1"] == pytest.approx(slope, abs=5 * se)
            # the report shows the same numbers (4 significant digits, 6 for coefficients)
            assert f"{e['rms_residual']:.4g}" in html
            assert f"{e['T1']:.6g}" in html
    assert csv.loc["U1", "pass"] and not csv.loc["U2", "pass"]
    assert list(pq["pass"]) == [True, False]
    reasons = str(csv.loc["U2", "fail_reasons"])
    assert "gx [deg/s].rms_residual" in reasons and "deg/s fails" in reasons
    assert "gy [rad/s].rms_after" in reasons and "rad/s fails" in reasons
    assert "az [mg].rms_residual" in reasons
    yield_row = html.split('id="yield-table"')[1].split("</table>")[0]
    assert "50.0 %" in yield_row


def test_a_limit_passes_just_inside_and_fails_just_outside(
    two_units: tuple[Path, dict[str, dict[str, dict[str, float]]]],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """Each channel's rms residual limit at its true value × (1 ± 10⁻⁶), in the channel's
    unit: passes above, fails below (a rerun with the new limits redoes the unit)."""
    _data, exp = two_units
    e = exp["U1"]
    cfg = tmp_path / "batch.toml"
    units: dict[str, tuple[str, str | None]] = {"U1": ("data/U1_mod.csv", None)}
    out = tmp_path / "out"
    for factor, passes in ((1 + 1e-6, True), (1 - 1e-6, False)):
        limits = "\n".join(
            f'[limits."{c}"]\nrms_residual_max = {e[c]["rms_residual"] * factor!r}' for c in UNITS
        )
        cfg.write_text(config_text(units, limits=limits), encoding="utf-8")
        code, res = _run(cfg, out, capsys)
        assert code == 0 and res["ok"] == 1
        assert res["passed"] == (1 if passes else 0)
        rec = json.loads((out / "units" / "U1" / "unit.json").read_text(encoding="utf-8"))
        assert rec["pass"] is passes
        if not passes:
            assert len(rec["fail_reasons"]) == 3
            assert "U1" in res["redone"] and "[limits]" in res["redone"]["U1"]


def test_a_figure_equal_to_its_limit_passes_and_a_missing_one_fails() -> None:
    """Limits are inclusive (``figure ≤ max``, ``≥ min``: INTERFACE.md's fleet limits); a
    figure that was not computed (None, NaN) fails its limit, never passes it; a channel
    limit judges only its channel."""
    from thermocal.fleet.batch import judge
    from thermocal.fleet.config import Limit

    figs = {"gx": {"rms_after": 0.05, "r": float("nan")}, "gy": {"rms_after": 0.07}}
    assert judge(figs, [Limit("rms_after", "max", 0.07)]) == []
    assert judge(figs, [Limit("rms_after", "min", 0.05)]) == []
    assert judge({"gx": {"r": 0.5}}, [Limit("r", "min", 0.5), Limit("r", "max", 0.5)]) == []
    assert len(judge(figs, [Limit("rms_after", "max", 0.06)])) == 1  # gy only
    assert judge(figs, [Limit("rms_after", "max", 0.06, channel="gx")]) == []
    assert len(judge({"gx": {"r": float("nan")}}, [Limit("r", "min", 0.0)])) == 1
    assert not Limit("r", "max", 1.0).check(None)
    # a limit on a channel the unit lacks, or on a figure it did not compute, fails
    (missing_channel,) = judge(figs, [Limit("rms_after", "max", 1.0, channel="gz")])
    assert "no channel 'gz'" in missing_channel
    (missing_figure,) = judge({"gx": {"rms_after": 0.05}}, [Limit("r", "min", 0.0)])
    assert missing_figure.startswith("gx.r ")
