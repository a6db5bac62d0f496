"""The stability results serialise themselves: ``AllanChannel.to_dict()`` and
``StabilityResult.to_dict()`` are what ``thermocal allan --json`` prints, key for key, and
their numbers agree with allantools (an independent implementation of NIST SP 1065)."""

from __future__ import annotations

import json
from pathlib import Path

import allantools
import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main
from thermocal.pipeline.messages import jsonable
from thermocal.readers import read_recording
from thermocal.readers.options import ReadOptions
from thermocal.stability.analysis import allan_analysis

SIGNAL = "gyro z deg/s"

ALLAN_KEYS = [
    "tau_s", "adev", "adev_low", "adev_high", "unit", "n_terms", "edf", "alpha",
    "alpha_method", "interval", "confidence", "tau0_s", "n_samples", "n_segments", "noise",
    "noise_method", "noise_slope", "noise_slope_method", "fit_coefficients",
    "fit_reduced_chi2", "fit_quality", "output_quantization", "bias_instability_minimum",
    "shaped_below_s", "periodic",
]  # fmt: skip
"""The keys ``allan --json`` printed before the builder moved into the library, in order."""


@pytest.fixture
def gyro(tmp_path: Path) -> tuple[Path, np.ndarray]:
    rng = np.random.default_rng(7)
    n = 8000
    t = np.arange(n) * 0.5  # 2 Hz
    rate = 1e-3 + rng.standard_normal(n) * 2e-4 + np.cumsum(rng.standard_normal(n)) * 2e-7
    path = tmp_path / "gyro.csv"
    pd.DataFrame({"time": t, SIGNAL: rate, "gx": rate[::-1].copy()}).to_csv(path, index=False)
    return path, rate


def _args(path: Path) -> list[str]:
    return ["allan", str(path), "--signal-unit", "deg/s", "--time-unit", "s", "--json"]


def _cli(args: list[str], capsys: pytest.CaptureFixture[str]) -> object:
    code = main(args)
    out = capsys.readouterr().out
    assert code == 0, out
    return json.loads(out)


def _library(path: Path, names: list[str], **kw: object):  # type: ignore[no-untyped-def]
    read = ReadOptions(time_unit="s", signals=tuple(names), signal_unit="deg/s", temperatures=())
    rec = read_recording(path, read, keep_other=False)
    return allan_analysis(rec, names, where=str(path), **kw)  # type: ignore[arg-type]


def _plain(obj: object) -> object:
    """What ``--json`` makes of a value: NaN → null, through the JSON text."""
    return json.loads(json.dumps(jsonable(obj), allow_nan=False))


def test_allan_channel_to_dict_is_the_cli_json(gyro, capsys) -> None:  # type: ignore[no-untyped-def]
    path, rate = gyro
    printed = _cli([*_args(path), "--signal", SIGNAL, "--dynamic", "1000"], capsys)
    d = _library(path, [SIGNAL], dynamic_s=1000.0).channels[SIGNAL].to_dict()
    assert list(d) == [*ALLAN_KEYS, "dynamic"]
    assert _plain(d) == printed
    taus, devs, _e, ns = allantools.oadev(rate, rate=2.0, data_type="freq", taus="octave")
    np.testing.assert_allclose(d["tau_s"], taus, rtol=1e-12)
    np.testing.assert_allclose(d["adev"], devs, rtol=1e-9)
    assert d["n_terms"] == ns.astype(int).tolist()
    assert list(d["noise"]["angle_random_walk"]) == [
        "value", "unit", "reason", "low", "high", "tau_s", "label", "quality", "method",
        "tau_range_s",
    ]  # fmt: skip
    assert d["noise"]["quantization"]["method"] == "fit"
    assert d["noise_slope"]["quantization"]["method"] == "slope"
    assert d["bias_instability_minimum"]["method"] == "minimum"
    assert d["dynamic"]["window_s"] == 1000.0 and d["dynamic"]["stationary"] is True


def test_several_channels_are_the_cli_json(gyro, capsys) -> None:  # type: ignore[no-untyped-def]
    path, _rate = gyro
    printed = _cli([*_args(path), "--signal", f"{SIGNAL},gx"], capsys)
    res = _library(path, [SIGNAL, "gx"])
    assert _plain({"channels": {n: c.to_dict() for n, c in res.channels.items()}}) == printed


def test_stability_result_to_dict_is_the_cli_json(gyro, capsys) -> None:  # type: ignore[no-untyped-def]
    path, rate = gyro
    printed = _cli([*_args(path), "--signal", SIGNAL, "--deviation", "mdev,hdev"], capsys)
    d = _library(path, [SIGNAL], deviations=["mdev", "hdev"]).family[SIGNAL].to_dict()
    assert _plain(d) == printed
    assert d["deviations"] == ["mdev", "hdev"]
    taus, mdevs, _e, ns = allantools.mdev(rate, rate=2.0, data_type="freq", taus="octave")
    np.testing.assert_allclose(d["mdev_tau_s"], taus, rtol=1e-12)
    assert d["mdev_n"] == ns.astype(int).tolist()
    np.testing.assert_allclose(d["mdev"], mdevs, rtol=1e-9)
    assert d["alpha"] == d["mdev_alpha"]  # the first Allan-family deviation's α
    assert d["mdev_interval"].startswith("chi-square, 68.3 %")
