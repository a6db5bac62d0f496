"""The figures of merit name their parameters; the ``metrics`` command shows its options.

``averaging_s``, ``latitude_deg``/``axis``, ``drift_reference_s``/``drift_bias`` and
``signal_unit`` for a Python user; ``--average``, ``--latitude``/``--axis``,
``--drift-reference``/``--drift-bias`` and ``--signal-unit`` on the command line.  The
longest averaging time that gives two averages is half the record, computed here.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main
from thermocal.errors import ParameterError, ThermocalInputError
from thermocal.metrics import (
    MetricsOptions,
    bias_stability,
    channel_metrics,
    compute_metrics,
    reference_bias,
)
from thermocal.pipeline.messages import error_text
from thermocal.recording import Recording

N = 200  # samples at 1 Hz: 200 s, half of it 100 s


def _recording() -> Recording:
    rng = np.random.default_rng(0)
    t = np.arange(N, dtype=np.float64)
    return Recording.from_arrays(
        t, {"gx": rng.normal(0, 1, N), "gy": rng.normal(0, 1, N)}, signal_unit="deg/h"
    )


def test_too_few_averages_names_averaging_s() -> None:
    half = N * 1.0 / 2.0
    with pytest.raises(ThermocalInputError) as caught:
        compute_metrics(_recording(), "gx", 300.0)
    assert str(caught.value).endswith(f"give averaging_s {half:.3g} or less")
    assert error_text(caught.value)[0].endswith(f"give --average {half:.3g} or less")
    rate = np.random.default_rng(1).normal(0, 1, N)
    with pytest.raises(ThermocalInputError) as caught:
        bias_stability(rate, 1.0, 300.0)
    assert str(caught.value) == (
        "bias stability needs at least two 300 s averages; the record gives 0; give "
        f"averaging_s {half:.3g} or less"
    )


def test_the_earth_rate_and_the_drift_name_their_parameters() -> None:
    rec = _recording()
    with pytest.raises(ThermocalInputError) as caught:
        compute_metrics(rec, "gx", latitude_deg=45.0)
    assert str(caught.value) == "earth-rate removal needs both latitude_deg and axis"
    assert error_text(caught.value)[0] == "earth-rate removal needs both --latitude and --axis"
    with pytest.raises(ThermocalInputError) as caught:
        channel_metrics(rec, ["gx", "gy"], MetricsOptions(latitude_deg=45.0, axis="up"))
    assert str(caught.value).startswith("earth-rate removal (latitude_deg/axis) takes one")
    assert str(caught.value).endswith("run metrics per gyro axis with its axis")
    assert error_text(caught.value)[0].startswith("earth-rate removal (--latitude/--axis)")
    with pytest.raises(ParameterError) as caught:
        compute_metrics(rec, "gx", drift_bias=math.nan)
    assert str(caught.value) == "drift_bias must be a number, got nan"
    with pytest.raises(ThermocalInputError) as caught:
        compute_metrics(rec, "gx", drift_bias=0.0, drift_reference_s=(0.0, 10.0))
    assert str(caught.value) == "give either drift_reference_s or drift_bias, not both"
    assert error_text(caught.value)[0] == (
        "give either --drift-reference or --drift-bias, not both"
    )
    t = np.arange(N, dtype=np.float64)
    with pytest.raises(ThermocalInputError) as caught:
        reference_bias(t, np.zeros(N), window_s=(300.0, 400.0))
    assert str(caught.value).endswith(
        f"(the run lasts {N - 1} s from its first sample); choose another drift_reference_s"
    )
    assert error_text(caught.value)[0].endswith("choose another --drift-reference")


def test_the_metrics_command_shows_its_options(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "g.csv"
    y = np.random.default_rng(2).normal(0, 1, N)
    path.write_text("time,gyro\n" + "".join(f"{i},{float(v)!r}\n" for i, v in enumerate(y)))
    base = ["metrics", str(path), "--signal", "gyro", "--signal-unit", "deg/h",
            "--time-unit", "s"]  # fmt: skip
    assert main([*base, "--latitude", "45"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["error: earth-rate removal needs both --latitude and --axis"]
    assert main([*base, "--average", "150"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].endswith("the record gives 1; give --average 100 or less"), err
