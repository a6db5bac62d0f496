"""The deviation registry: a toy deviation added by one ``register`` call is computed by the
library (``thermocal.stability.deviation``) and the command line (``allan --deviation``)."""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import numpy.typing as npt
import pandas as pd
import pytest
from scipy import stats

from thermocal import stability
from thermocal.cli import main
from thermocal.errors import ParameterError, ThermocalInputError
from thermocal.stability import registry


def _toy_sums(
    x: npt.NDArray[np.float64], tau0_s: float, m: npt.NDArray[np.int64]
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """The sample variance of the non-overlapping τ-averages (the classical deviation)."""
    num = np.zeros(m.size)
    cnt = np.zeros(m.size)
    for i, mm in enumerate(m.tolist()):
        k = (x.size - 1) // mm
        if k < 2:
            continue
        avg = np.diff(x[: k * mm + 1 : mm]) / (mm * tau0_s)
        num[i] = float(np.sum((avg - avg.mean()) ** 2))
        cnt[i] = k - 1
    return num, cnt


TOY = registry.Deviation(
    "toystd",
    _toy_sums,
    lambda n_phase: (n_phase - 1) // 2,
    lambda alpha, m, n_phase: float((n_phase - 1) // m - 1),
    interval="chi-square with K - 1 degrees of freedom (white noise)",
    data_types=("rate",),
    reference="the sample standard deviation of τ-averages",
)


@pytest.fixture
def toy() -> Iterator[registry.Deviation]:
    registry.register(TOY)
    yield TOY
    registry.unregister("toystd")


def _expected(y: np.ndarray, m: int) -> tuple[float, int]:
    """numpy's own: the standard deviation (ddof 1) of the non-overlapping m-averages."""
    k = y.size // m
    return float(y[: k * m].reshape(k, m).mean(axis=1).std(ddof=1)), k - 1


def test_a_registered_toy_deviation_is_computed_by_the_library(toy: registry.Deviation) -> None:
    y = np.random.default_rng(7).normal(3.0, 0.5, 4000)
    r = stability.deviation("toystd", y, rate_hz=10.0, taus=[0.1, 0.4, 1.6])
    assert r.m.tolist() == [1, 4, 16]
    for i, mm in enumerate(r.m.tolist()):
        dev, dof = _expected(y, mm)
        assert r.dev[i] == pytest.approx(dev, rel=1e-9)
        assert r.edf[i] == dof
        c = r.confidence
        lo = dev * np.sqrt(dof / stats.chi2.ppf((1 + c) / 2, dof))
        hi = dev * np.sqrt(dof / stats.chi2.ppf((1 - c) / 2, dof))
        assert (r.low[i], r.high[i]) == pytest.approx((lo, hi), rel=1e-9)
    assert "toystd" in stability.names()


def test_the_toy_deviation_refuses_phase_data_it_does_not_take(toy: registry.Deviation) -> None:
    with pytest.raises(ParameterError, match="data_type 'phase': toystd takes rate"):
        stability.deviation("toystd", np.arange(100.0), rate_hz=1.0, data_type="phase")


def test_the_toy_deviation_runs_through_the_command_line(
    toy: registry.Deviation, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    y = np.random.default_rng(8).normal(0.0, 0.2, 3000)
    path = tmp_path / "rate.csv"
    pd.DataFrame({"time": np.arange(y.size) * 0.5, "gyro_z": y}).to_csv(path, index=False)
    code = main(["allan", str(path), "--signal", "gyro_z", "--deviation", "toystd,oadev",
                 "--taus", "2,8", "--json"])  # fmt: skip
    out = capsys.readouterr().out
    assert code == 0, out
    obj = json.loads(out)
    got = obj["toystd"]
    assert [_expected(y, 4)[0], _expected(y, 16)[0]] == pytest.approx(got, rel=1e-9)
    assert obj["toystd_interval"].endswith("chi-square with K - 1 degrees of freedom (white noise)")


def test_an_unknown_or_taken_name_is_refused_naming_the_parameter() -> None:
    with pytest.raises(ParameterError, match="deviation 'nodev': unknown; use oadev, adev"):
        stability.deviation("nodev", np.zeros(10), rate_hz=1.0)
    with pytest.raises(ParameterError, match="'oadev' is registered already"):
        registry.register(registry.get("oadev"))


def test_a_toy_deviation_without_a_work_estimate_costs_four_operations_a_point(
    toy: registry.Deviation,
) -> None:
    """Every factor of m = 1 … 2000 on 4001 phase points: 4 · 4001 · 2000 = 3.2e7 operations."""
    assert toy.estimated_work(4001, np.arange(1, 2001)) == 4.0 * 4001 * 2000
    y = np.random.default_rng(9).normal(size=4000)
    with pytest.raises(ThermocalInputError, match=r"needs about 3\.2e\+07 operations"):
        stability.deviation("toystd", y, rate_hz=1.0, taus="all", max_work=1e7)
