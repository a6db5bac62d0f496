"""The library functions the analysis commands call (issue 27: thin CLI), tested without the
command line: :func:`thermocal.stability.analysis.allan_analysis` and ``imu_noise``,
:func:`thermocal.metrics.channel_metrics` and ``power_on_metrics``,
:func:`thermocal.simulate.simulate_scenario`.  Every expected number is computed here
from its textbook formula, not by the package."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy import stats

from thermocal.cli.allan_cmd import parse_taus
from thermocal.errors import ConditioningWarning, ThermocalInputError
from thermocal.metrics import MetricsOptions, channel_metrics, power_on_metrics
from thermocal.recording import Recording
from thermocal.simulate import SimulateOptions, simulate_scenario
from thermocal.stability.analysis import (
    allan_analysis,
    column_unit,
    imu_noise,
)


def _overlapping_adev(y: np.ndarray, m: int) -> float:
    """NIST SP 1065 eq. 11 from the averages of m samples (not through the phase):
    σ² = Σ_k (ȳ_{k+m} − ȳ_k)² / (2 (N − 2m + 1))."""
    c = np.concatenate([[0.0], np.cumsum(y)])
    ybar = (c[m:] - c[:-m]) / m  # ȳ_k for k = 0 … N − m
    d = ybar[m:] - ybar[:-m]
    return math.sqrt(float(np.sum(d**2)) / (2.0 * d.size))


def _non_overlapping_adev(y: np.ndarray, m: int) -> float:
    """σ² = Σ_j (ȳ_{j+1} − ȳ_j)² / (2 (M − 1)) over M = ⌊N/m⌋ block means."""
    k = y.size // m
    blocks = y[: k * m].reshape(k, m).mean(axis=1)
    return math.sqrt(float(np.sum(np.diff(blocks) ** 2)) / (2.0 * (k - 1)))


def _rate_recording(n: int = 4096, tau0: float = 0.5, unit: str = "deg/h") -> Recording:
    rng = np.random.default_rng(7)
    t = np.arange(n) * tau0
    return Recording.from_arrays(
        t,
        {"gx": 3.0 + rng.normal(0.0, 0.2, n), "gy": -1.0 + rng.normal(0.0, 0.05, n)},
        signal_unit=unit,
    )


def test_allan_analysis_gives_the_overlapping_adev_of_each_channel() -> None:
    rec = _rate_recording()
    y = {n: rec.column(n).copy() for n in ("gx", "gy")}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConditioningWarning)
        res = allan_analysis(rec, ["gx", "gy"], taus=[0.5, 2.0, 8.0], where="mem")
    assert not res.is_family and res.names == ("gx", "gy")
    for name in ("gx", "gy"):
        ch = res.channels[name]
        np.testing.assert_allclose(ch.adev.tau_s, [0.5, 2.0, 8.0], rtol=0, atol=1e-12)
        want = [_overlapping_adev(y[name], m) for m in (1, 4, 16)]
        np.testing.assert_allclose(ch.adev.adev, want, rtol=1e-9, atol=0)
        assert ch.adev.unit == "deg/h" and ch.dynamic is None


def test_allan_analysis_reports_in_the_columns_own_unit() -> None:
    # deg/s data: the ADEV in deg/s (not the canonical deg/h, 3600 times larger)
    rec = _rate_recording(unit="deg/s")
    y = rec.column("gx").copy()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConditioningWarning)
        res = allan_analysis(rec, ["gx"], taus=[1.0])
    ch = res.channels["gx"]
    assert ch.adev.unit == "deg/s"
    assert ch.adev.adev[0] == pytest.approx(_overlapping_adev(y, 2), rel=1e-9)


def test_allan_analysis_family_gives_the_deviations_asked() -> None:
    rec = _rate_recording()
    y = rec.column("gy").copy()
    res = allan_analysis(rec, ["gy"], taus=[1.0, 4.0], deviations=["adev", "oadev"])
    assert res.is_family and not res.channels
    fam = res.family["gy"]
    np.testing.assert_allclose(
        fam.curves["adev"].dev, [_non_overlapping_adev(y, m) for m in (2, 8)], rtol=1e-9
    )
    np.testing.assert_allclose(
        fam.curves["oadev"].dev, [_overlapping_adev(y, m) for m in (2, 8)], rtol=1e-9
    )


def test_allan_analysis_checks_its_options() -> None:
    rec = _rate_recording()
    with pytest.raises(ThermocalInputError, match="use rate or phase"):
        allan_analysis(rec, ["gx"], data_type="angle")
    with pytest.raises(ThermocalInputError, match="dynamic_s computes"):
        allan_analysis(rec, ["gx"], deviations=["mdev"], dynamic_s=100.0)
    assert parse_taus("decade") == "decade"
    assert parse_taus("1, 10,100") == [1.0, 10.0, 100.0]
    with pytest.raises(ThermocalInputError, match="--taus"):
        parse_taus("1,ten")
    assert column_unit("angle (deg)") == "deg" and column_unit("phase [s]") == "s"
    assert column_unit("phase") == ""


def test_imu_noise_reads_the_white_noise_density() -> None:
    # white noise of σ per sample at f_s: N = σ/√f_s [rad/s/√Hz] (IEEE 952 C.1, σ² = N²/τ)
    fs, sigma, n = 100.0, 0.01, 200_000
    rng = np.random.default_rng(3)
    t = np.arange(n) / fs
    rec = Recording.from_arrays(
        t, {c: rng.normal(0.0, sigma, n) for c in ("wx", "wy", "wz")}, signal_unit="rad/s"
    )
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ConditioningWarning)
        res = imu_noise(rec, ["wx", "wy", "wz"], [], where="mem")
    assert [a.name for a in res.axes] == ["wx", "wy", "wz"]
    # white noise alone: the random walk is only bounded, and each axis says so
    bounded = [a.name for a in res.axes if a.walk.method == "bound"]
    assert bounded, "a white-noise record shows no random walk"
    said = [str(w.message) for w in caught if issubclass(w.category, ConditioningWarning)]
    for name in bounded:
        assert any(m.startswith(f"mem [{name}]: ") for m in said), said
    for ax in res.axes:
        assert ax.sensor == "gyro" and ax.density.unit.startswith("rad/s")
        # ~2 % sampling error of the τ = 1 s point with 10^5 terms; 5 % is far outside it
        assert ax.density.value == pytest.approx(sigma / math.sqrt(fs), rel=0.05)
    assert res.model.update_rate_hz == pytest.approx(fs, rel=1e-9)


def _metrics_recording(offset: float, seed: int) -> Recording:
    rng = np.random.default_rng(seed)
    n = 1200
    t = np.arange(n) * 1.0
    return Recording.from_arrays(
        t,
        {"gz": offset + rng.normal(0.0, 0.3, n), "ax": 5.0 + rng.normal(0.0, 0.1, n)},
        signal_unit={"gz": "deg/h", "ax": "mg"},
    )


def test_channel_metrics_bias_and_stability_per_channel() -> None:
    rec = _metrics_recording(1.5, 1)
    y = {n: rec.column(n).copy() for n in ("gz", "ax")}
    res = channel_metrics(rec, ["gz", "ax"], MetricsOptions(averaging_s=10.0))
    assert list(res) == ["gz", "ax"]
    for name in ("gz", "ax"):
        blocks = y[name].reshape(120, 10).mean(axis=1)
        assert res[name].bias == pytest.approx(float(np.mean(y[name])), rel=1e-12)
        assert res[name].bias_stability == pytest.approx(float(np.std(blocks, ddof=1)), rel=1e-9)
        assert res[name].peak_to_peak == pytest.approx(float(np.ptp(blocks)), rel=1e-9)
    assert res["ax"].unit == "mg" and res["ax"].drift_angle is None
    with pytest.raises(ThermocalInputError, match="one signal at a time"):
        channel_metrics(rec, ["gz", "ax"], MetricsOptions(latitude_deg=45.0, axis="z"))


def test_power_on_metrics_reads_each_run_and_gives_the_repeatability() -> None:
    offsets = {"a.csv": 1.0, "b.csv": 1.4, "c.csv": 0.7}
    recs = {f: _metrics_recording(o, i) for i, (f, o) in enumerate(offsets.items())}
    means = [float(np.mean(r.column("gz"))) for r in recs.values()]
    read: list[str] = []

    def reader(f: str) -> Recording:
        read.append(f)
        return recs[f]

    res = power_on_metrics(list(offsets), reader, ["gz"], MetricsOptions())
    assert read == list(offsets) and res.names == ("gz",)
    rep = res.repeatability["gz"]
    s = float(np.std(means, ddof=1))
    assert rep.bias_repeatability == pytest.approx(s, rel=1e-12)
    assert rep.bias_mean == pytest.approx(float(np.mean(means)), rel=1e-12)
    # chi-square interval of a standard deviation, ν = 2, 68.27 %
    p = (1.0 - math.erf(1.0 / math.sqrt(2.0))) / 2.0
    assert rep.bias_repeatability_low == pytest.approx(
        s * math.sqrt(2.0 / stats.chi2.ppf(1.0 - p, 2)), rel=1e-9
    )
    assert rep.bias_repeatability_high == pytest.approx(
        s * math.sqrt(2.0 / stats.chi2.ppf(p, 2)), rel=1e-9
    )
    assert rep.files == tuple(offsets)


def test_power_on_metrics_stops_at_the_first_run_with_other_signals() -> None:
    recs = {"a": _metrics_recording(1.0, 1), "b": _metrics_recording(1.0, 2)}
    read: list[str] = []

    def reader(f: str) -> Recording:
        read.append(f)
        return recs[f]

    # default signal: each file's first; both have gz first, so they agree
    res = power_on_metrics(["a", "b"], reader, None, MetricsOptions())
    assert res.names == ("gz",)
    recs["b"] = Recording.from_arrays(np.arange(100.0), {"gy": np.zeros(100)})
    with pytest.raises(ThermocalInputError, match=r"b: signals \['gy'\] differ"):
        power_on_metrics(["a", "b"], reader, None, MetricsOptions())


def test_simulate_scenario_labels_and_truth_document() -> None:
    opts = SimulateOptions(rate_hz=0.01, runs=2)
    sim = simulate_scenario("accel-full-range", 4, None, opts)
    assert len(sim.results) == 2 == len(sim.labels)
    assert len(set(sim.labels)) == 2
    doc = sim.truth_document(["x.csv", "y.csv"], None)
    assert doc["format"] == "thermocal-truth" and doc["version"] == 1
    assert doc["scenario"] == "accel-full-range" and doc["seed"] == 4
    assert [f["file"] for f in doc["files"]] == ["x.csv", "y.csv"]
    assert opts.given() == {"rate_hz": 0.01, "runs": 2}
    with pytest.raises(ThermocalInputError, match=r"^rate_hz must be a positive number"):
        SimulateOptions(rate_hz=0.0)
    with pytest.raises(ThermocalInputError, match=r"^latitude_deg "):
        SimulateOptions(latitude_deg=91.0)


def test_simulate_scenario_numbers_runs_whose_labels_collide(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    import thermocal.simulate.scenarios as sc

    rec = Recording.from_arrays(np.arange(10.0), {"g": np.zeros(10)})
    monkeypatch.setattr(
        sc, "run_scenario", lambda *a, **k: [(rec, {"label": "T+25"}), (rec, {"label": "T+25"})]
    )
    assert simulate_scenario("fog-slow", 0, None, SimulateOptions()).labels == ("1", "2")
    monkeypatch.setattr(
        sc, "run_scenario", lambda *a, **k: [(rec, {"label": "T+25"}), (rec, {"label": "T-5"})]
    )
    assert simulate_scenario("fog-slow", 0, None, SimulateOptions()).labels == ("T+25", "T-5")


@pytest.mark.parametrize("deviations", [None, ["oadev", "mdev"]])
def test_allan_analysis_leaves_the_callers_arrays_as_they_were(
    deviations: list[str] | None,
) -> None:
    """A notebook user's arrays are theirs: ``Recording.from_arrays`` keeps them without a
    copy, and the analysis must not accumulate its phase in them (the ``allan`` command, which
    reads its own recording, asks for that with ``overwrite=True``)."""
    y = np.random.default_rng(3).normal(0.0, 1.0, 20_000)
    kept = y.copy()
    rec = Recording.from_arrays(np.arange(y.size) * 0.01, {"gx": y}, {})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = allan_analysis(rec, ["gx"], deviations=deviations)
        assert np.array_equal(y, kept)
        if deviations is None:  # the overlapping ADEV at τ0 = rms of first differences / √2
            first = float(res.channels["gx"].adev.adev[0])
            assert first == pytest.approx(np.sqrt(np.mean(np.diff(kept) ** 2) / 2), rel=1e-9)
            allan_analysis(rec, ["gx"], overwrite=True)  # the command's way: given up
            assert not np.array_equal(y, kept)
