"""The figures of merit serialise themselves: ``MetricsResult.to_dict()`` and
``RunRepeatability.to_dict()`` are what ``thermocal metrics --json`` prints, key for key,
and their numbers agree with numpy computed here (mean, sample standard deviation)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.cli import main
from thermocal.metrics import MetricsOptions, channel_metrics, power_on_metrics
from thermocal.pipeline.messages import jsonable
from thermocal.readers import read_recording
from thermocal.readers.options import ReadOptions
from thermocal.recording import Recording

SIGNAL = "gyro z deg/s"
READ = ReadOptions(
    time_unit="s", signals=(SIGNAL,), signal_unit="deg/s", temperatures=("T1",), temp_unit="degC"
)

METRICS_KEYS = [
    "bias", "bias_stability", "averaging_s", "peak_to_peak", "unit", "temperature_sensitivity",
    "bias_repeatability", "drift_angle_max", "drift_angle_max_time_s", "drift_angle",
    "drift_angle_unit", "drift_reference", "earth_rate_removed", "n_stages", "stages",
    "n_samples", "n_segments", "n_averages", "duration_s", "signal",
]  # fmt: skip
"""The keys ``metrics --json`` printed before the builder moved into the library, in order."""


def _write(path: Path, offset: float, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    n = 6000
    t = np.arange(n) * 0.5  # 2 Hz, two 1500 s holds at 20 and 40 °C
    temp = np.where(t < 1500.0, 20.0, 40.0)
    rate = offset + 1e-5 * temp + rng.standard_normal(n) * 1e-4
    pd.DataFrame({"time": t, SIGNAL: rate, "T1": temp}).to_csv(path, index=False)
    return rate


def _cli(args: list[str], capsys: pytest.CaptureFixture[str]) -> object:
    code = main(args)
    out = capsys.readouterr().out
    assert code == 0, out
    return json.loads(out)


def _plain(obj: object) -> object:
    """What ``--json`` makes of a value: NaN → null, through the JSON text."""
    return json.loads(json.dumps(jsonable(obj), allow_nan=False))


ARGS = ["--signal", SIGNAL, "--signal-unit", "deg/s", "--time-unit", "s", "--temps", "T1",
        "--temp-unit", "degC", "--average", "10", "--min-hold", "600", "--json"]  # fmt: skip
OPTIONS = MetricsOptions(averaging_s=10.0, temps=("T1",), min_hold_s=600.0)


def test_metrics_result_to_dict_is_the_cli_json(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    path = tmp_path / "run.csv"
    rate = _write(path, 1e-3, 0)
    printed = _cli(["metrics", str(path), *ARGS], capsys)
    rec = read_recording(path, READ, keep_other=False)
    d = channel_metrics(rec, [SIGNAL], OPTIONS)[SIGNAL].to_dict()
    assert list(d) == METRICS_KEYS
    assert _plain(d) == printed
    assert d["bias"] == pytest.approx(rate.mean(), rel=1e-12)
    blocks = rate.reshape(-1, 20).mean(axis=1)
    assert d["bias_stability"] == pytest.approx(np.std(blocks, ddof=1), rel=1e-9)
    assert d["n_stages"] == 2 and len(d["stages"]) == 2
    assert [s["mean_temp_c"] for s in d["stages"]] == pytest.approx([20.0, 40.0])
    assert isinstance(d["temperature_sensitivity"]["temps_c"], list)


def test_run_repeatability_to_dict_is_the_cli_json(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    paths = [tmp_path / f"on{k}.csv" for k in range(3)]
    offsets = (1e-3, 3e-3, 2e-3)
    means = [_write(p, offsets[k], k).mean() for k, p in enumerate(paths)]
    printed = _cli(["metrics", *map(str, paths), *ARGS], capsys)

    def read(p: Path) -> Recording:
        return read_recording(p, READ, keep_other=False)

    res = power_on_metrics(paths, read, [SIGNAL], OPTIONS)
    d = res.repeatability[SIGNAL].to_dict()
    assert _plain(d) == printed
    assert [r["file"] for r in d["runs"]] == [str(p) for p in paths]
    assert list(d["runs"][0]) == ["file", *METRICS_KEYS]
    assert d["n_runs"] == 3
    assert d["bias"] == pytest.approx(np.mean(means), rel=1e-12)
    assert d["bias_repeatability"] == pytest.approx(np.std(means, ddof=1), rel=1e-9)
    assert d["bias_stability"] == max(r["bias_stability"] for r in d["runs"])
