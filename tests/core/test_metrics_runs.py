"""``thermocal metrics FILE...``: separate power-ons give each run's bias and in-run bias
stability and the turn-on to turn-on bias repeatability with its chi-square interval
(issue 29 item 5), in the data's own unit, against numpy and scipy.stats here."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from scipy import stats

from thermocal.cli import main

TURN_ON_BIAS_DEG_S = (0.0123, 0.0191, 0.0087, 0.0150, 0.0112)  # each power-on's bias [°/s]
FS_HZ = 10.0
RUN_S = 600.0
AVERAGE_S = 10.0


def _runs(tmp_path: Path) -> tuple[list[Path], list[np.ndarray]]:
    rng = np.random.default_rng(31)
    n = int(RUN_S * FS_HZ)
    paths, data = [], []
    for i, b in enumerate(TURN_ON_BIAS_DEG_S):
        y = b + rng.normal(0.0, 0.004, n) + 1e-6 * np.arange(n)  # white noise, a small drift
        p = tmp_path / f"power_on_{i}.csv"
        t = np.arange(n) / FS_HZ
        lines = [
            "time [s],gyro z [deg/s]",
            *(f"{a:.3f},{v:.9g}" for a, v in zip(t, y, strict=True)),
        ]
        p.write_text("\n".join(lines) + "\n", encoding="utf-8")
        paths.append(p)
        data.append(np.array([float(f"{v:.9g}") for v in y]))
    return paths, data


def test_turn_on_repeatability_against_numpy(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    paths, data = _runs(tmp_path)
    code = main(
        ["metrics", *map(str, paths), "--time", "time [s]", "--signal", "gyro z [deg/s]",
         "--average", str(AVERAGE_S), "--json"]
    )  # fmt: skip
    assert code == 0
    out = json.loads(capsys.readouterr().out)
    assert out["unit"] == "deg/s"
    assert out["n_runs"] == len(paths)
    biases = np.array([d.mean() for d in data])
    m = int(AVERAGE_S * FS_HZ)
    stabilities = [d[: d.size // m * m].reshape(-1, m).mean(axis=1).std(ddof=1) for d in data]
    for run, p, b, s in zip(out["runs"], paths, biases, stabilities, strict=True):
        assert run["file"] == str(p)
        assert run["bias"] == pytest.approx(b, rel=1e-9)
        assert run["bias_stability"] == pytest.approx(s, rel=1e-9)
    rep = biases.std(ddof=1)
    nu = len(biases) - 1
    lo = rep * math.sqrt(nu / stats.chi2.ppf(0.5 + 0.6827 / 2, nu))
    hi = rep * math.sqrt(nu / stats.chi2.ppf(0.5 - 0.6827 / 2, nu))
    assert out["bias_repeatability"] == pytest.approx(rep, rel=1e-9)
    # the known turn-on biases' own spread, within the interval the runs give
    assert out["bias_repeatability"] == pytest.approx(np.std(TURN_ON_BIAS_DEG_S, ddof=1), rel=0.05)
    assert out["bias_repeatability_low"] == pytest.approx(lo, rel=1e-3)
    assert out["bias_repeatability_high"] == pytest.approx(hi, rel=1e-3)
    assert out["bias"] == pytest.approx(biases.mean(), rel=1e-9)


def test_one_file_keeps_its_keys_and_mixed_units_are_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    paths, _ = _runs(tmp_path)
    sig = ["--time", "time [s]", "--signal", "gyro z [deg/s]", "--json"]
    assert main(["metrics", str(paths[0]), *sig]) == 0
    one = json.loads(capsys.readouterr().out)
    assert "runs" not in one and one["unit"] == "deg/s"
    other = tmp_path / "rad.csv"
    other.write_text(paths[1].read_text(encoding="utf-8"), encoding="utf-8")
    (tmp_path / "rad.csv.meta.json").write_text(
        json.dumps({"signals": {"gyro z [deg/s]": "rad/s"}}), encoding="utf-8"
    )
    code = main(["metrics", str(paths[0]), str(other), *sig])
    assert code == 2
    err = capsys.readouterr().err
    assert str(other) in err and "one unit" in err, err
