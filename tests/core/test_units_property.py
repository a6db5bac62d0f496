"""Property (issue 13): whatever units a user writes the same physical data in — °/s, °/h,
rad/s for a gyro; mg, g, m/s² for an accelerometer; time in s, ms or µs; temperatures in °C
or raw counts with a conversion (plain or signed 16-bit) — and however each unit is stated
(option, sidecar, column name) and whether the options are repeated on later commands,
fit → compensate → validate gives the same physical result.

The reference is the same data in the canonical units (°/h or mg, s, °C), every unit given
as an option.  The model uses T, T² and Ṫ (Δt = 60.5 s, so no sample sits on the window's
edge where a rounding of the time conversion could move it), so a time unit lost on the
way changes Ṫ by 10³ or 10⁶ and the test fails.
"""

from __future__ import annotations

import json
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from thermocal import units
from thermocal.cli import main

N = 1500
RATE_UNITS = ["deg/s", "deg/h", "rad/s"]
ACCEL_UNITS = ["mg", "g", "m/s^2"]
TIME_FACTOR = {"s": 1.0, "ms": 1e3, "us": 1e6}  # value in that unit per second (exact)
CONVERSIONS = {
    "plain": (0.0625, -50.0, ""),  # T = 0.0625·v − 50
    "int16": (0.0625, 25.0, "int16"),  # v signed: negative below 25 °C, stored + 65536
}
MODEL = ["--model", "poly", "--terms", "T1,T1^2,dT1", "--rate-interval", "60.5"]


def _physical(kind: str) -> dict[str, np.ndarray]:
    """One run in canonical units: time [s], T [°C] on a 1/16 °C grid (so every raw count
    is an integer), signal [°/h] or [mg] = quadratic in T + a Ṫ term + noise."""
    rng = np.random.default_rng(7)
    t = np.arange(N, dtype=float)
    temp = 25.0 + 14.0 * np.sin(2 * np.pi * t / N) + 3.0 * np.sin(2 * np.pi * t / 317.0)
    temp = np.round(temp * 16.0) / 16.0
    # a thermal-gradient effect in the backward 60 s difference Ṫ [°C/min] (SPEC §3)
    lag = np.maximum(np.arange(N) - 60, 0)
    span = t - t[lag]
    dtemp = np.divide(temp - temp[lag], span, out=np.zeros(N), where=span > 0) * 60.0
    if kind == "rate":
        sig = 30.0 + 0.8 * (temp - 25.0) + 0.01 * (temp - 25.0) ** 2 + 2.0 * dtemp
        sig += 0.05 * rng.standard_normal(N)
    else:
        sig = 4.0 + 0.03 * (temp - 25.0) - 0.002 * (temp - 25.0) ** 2 + 0.5 * dtemp
        sig += 0.01 * rng.standard_normal(N)
    return {"time": t, "temp": temp, "signal": sig}


def _counts(temp: np.ndarray, enc: str) -> np.ndarray:
    gain, offset, _ = CONVERSIONS[enc]
    v = np.round((temp - offset) / gain)
    return np.where(v < 0, v + 65536.0, v) if enc == "int16" else v


def _conv_text(enc: str) -> str:
    gain, offset, flag = CONVERSIONS[enc]
    return ",".join([repr(gain), repr(offset), *([flag] if flag else [])])


def _run(*args: str) -> tuple[int, str, str]:
    import contextlib
    import io

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(args))
    return code, out.getvalue(), err.getvalue()


def _pipeline(d: Path, kind: str, choice: dict[str, Any]) -> dict[str, Any]:
    """Write the physical data as ``choice`` says, fit, compensate and validate through the
    CLI; return the model values and figures converted to canonical units."""
    phys = _physical(kind)
    su, tu, temp_mode = choice["signal_unit"], choice["time_unit"], choice["temp"]
    how = choice["how"]  # (signal, time, temperature) → "option" | "sidecar" | "name"
    canon = units.canonical_unit(su)
    to_data = 1.0 / units.convert(1.0, su, canon)  # canonical → data unit
    sig_col = f"sig [{su}]" if how["signal"] == "name" else "sig"
    time_col = f"time ({tu})" if how["time"] == "name" else "time"
    temp_col = "T1"
    counts = temp_mode != "degC"
    if counts and how["temp"] == "name":
        temp_col = "T1_counts"
    data = pd.DataFrame(
        {
            time_col: phys["time"] * TIME_FACTOR[tu],
            sig_col: phys["signal"] * to_data,
            temp_col: _counts(phys["temp"], temp_mode) if counts else phys["temp"],
        }
    )
    src = d / "run.csv"
    data.to_csv(src, index=False)
    side: dict[str, Any] = {}
    if how["signal"] == "sidecar":
        side["signals"] = {sig_col: su}
    if how["time"] == "sidecar":
        side["time_unit"] = tu
    if how["temp"] == "sidecar":
        side["temperatures"] = {temp_col: "counts" if counts else "degC"}
        if counts:
            gain, offset, flag = CONVERSIONS[temp_mode]
            side["metadata"] = {
                "temperature_conversion": {temp_col: [gain, offset, *([flag] if flag else [])]}
            }
    if side:
        (d / "run.csv.meta.json").write_text(json.dumps(side))
    opts: list[str] = []  # unit options of the fit (the others are in the file)
    if how["signal"] == "option":
        opts += ["--signal-unit", su]
    if how["time"] == "option":
        opts += ["--time-unit", tu]
    if counts and how["temp"] in ("option", "name"):
        opts += ["--temp-conversion", _conv_text(temp_mode)]
    if not counts and how["temp"] == "option":
        opts += ["--temp-unit", "degC"]
    base = ["--time", time_col]
    model = d / "m.json"
    code, _, err = _run(
        "fit", str(src), *MODEL, "--signal", sig_col, "--temps", temp_col, *base, *opts,
        "-o", str(model),
    )  # fmt: skip
    assert code == 0, err
    assert "no unit stated" not in err, err
    later = opts if choice["repeat"] else []
    out = d / "comp.csv"
    code, _, err = _run("compensate", str(model), str(src), *base, *later, "-o", str(out))
    assert code == 0, err
    assert "no unit stated" not in err, err
    comp = pd.read_csv(out)
    code, stdout, err = _run("validate", str(model), str(src), *base, *later, "--json")
    assert code == 0, err
    val = json.loads(stdout)
    assert val["unit"] == su  # figures in the data's own unit
    return {
        "model": comp[f"{sig_col}_model"].to_numpy() / to_data,
        "comp": comp[f"{sig_col}_comp"].to_numpy() / to_data,
        **{k: val[k] / to_data for k in ("rms_before", "rms_after", "peak_to_peak_after")},
    }


_REFERENCE: dict[str, dict[str, Any]] = {}


def _reference(kind: str) -> dict[str, Any]:
    if kind not in _REFERENCE:
        with tempfile.TemporaryDirectory() as tmp:
            _REFERENCE[kind] = _pipeline(
                Path(tmp),
                kind,
                {
                    "signal_unit": "deg/h" if kind == "rate" else "mg",
                    "time_unit": "s",
                    "temp": "degC",
                    "how": {"signal": "option", "time": "option", "temp": "option"},
                    "repeat": True,
                },
            )
    return _REFERENCE[kind]


HOW = st.sampled_from(["option", "sidecar", "name"])


@st.composite
def choices(draw: st.DrawFn) -> dict[str, Any]:
    kind = draw(st.sampled_from(["rate", "accel"]))
    return {
        "kind": kind,
        "signal_unit": draw(st.sampled_from(RATE_UNITS if kind == "rate" else ACCEL_UNITS)),
        "time_unit": draw(st.sampled_from(list(TIME_FACTOR))),
        "temp": draw(st.sampled_from(["degC", "plain", "int16"])),
        "how": {"signal": draw(HOW), "time": draw(HOW), "temp": draw(HOW)},
        "repeat": draw(st.booleans()),
    }


@settings(max_examples=15, deadline=None, derandomize=True)
@given(choice=choices())
def test_same_physical_result_whatever_the_units(choice: dict[str, Any]) -> None:
    ref = _reference(choice["kind"])
    with tempfile.TemporaryDirectory() as tmp:
        got = _pipeline(Path(tmp), choice["kind"], choice)
    for key in ("model", "comp"):
        scale = float(np.max(np.abs(ref[key])))
        np.testing.assert_allclose(got[key], ref[key], rtol=1e-9, atol=1e-9 * scale)
    for key in ("rms_before", "rms_after", "peak_to_peak_after"):
        assert got[key] == pytest.approx(ref[key], rel=1e-9), key


def test_the_reference_is_a_real_model() -> None:
    """The comparison above is not vacuous: the model removes most of the temperature
    effect, including the Ṫ term (a wrong time unit would leave it)."""
    for kind in ("rate", "accel"):
        ref = _reference(kind)
        assert ref["rms_after"] < 0.05 * ref["rms_before"]
