"""Compensation: batch, chunked files and streaming agree (SPEC §4, §8; issue 6).

A toy model defined here (not registered, so other tests never see it) has the
two kinds of state the real families carry: a backward Ṫ buffer (poly) and a
T0 captured as a running mean over a start window, frozen afterwards (warmup).
The real families are tested the same way further down, for every family that
is registered.
"""

from __future__ import annotations

import itertools
import json
import math
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any, Self

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

from thermocal import units
from thermocal.compensate.kernels import (
    ChunkPredictor,
    StreamingCompensator,
    compensate_run,
    unit_factor,
)
from thermocal.errors import (
    ExtrapolationWarning,
    MissingColumnError,
    ThermocalInputError,
    TimestampError,
    UnitError,
)
from thermocal.models.base import ChunkContext, ModelStream, TemperatureModel
from thermocal.models.registry import MODEL_REGISTRY, make_model
from thermocal.models.results import Coefficient, FitStats
from thermocal.models.rundata import RunData
from thermocal.pipeline.compensate import compensate_file
from thermocal.preprocess import temperature_rate
from thermocal.readers.common import csv_float_options
from thermocal.readers.options import ReadOptions
from thermocal.recording import GAP_FACTOR, FloatArray

# --- a toy model with a rate buffer and a start-up state ------------------------------------

# The library-built models here carry no fitted input units and the files no metadata:
# the stated-default warnings are tested in test_units_travel.py.
pytestmark = pytest.mark.filterwarnings("ignore::thermocal.errors.UnitWarning")


class ToyModel(TemperatureModel):
    """y = a·(T1 − T0) + b·Ṫ1 + c·T2², T0 = running mean of T1 over the first window_s."""

    family = "toy-test"
    uses_rate = True

    def __init__(
        self,
        a: float = 0.3,
        b: float = 2.0,
        c: float = 0.001,
        rate_interval_s: float = 30.0,
        window_s: float = 20.0,
    ) -> None:
        self.a = a
        self.b = b
        self.c = c
        self.rate_interval_s = rate_interval_s
        self.window_s = window_s

    def fit(self, runs: Sequence[RunData]) -> Self:
        self._record_common(runs, FitStats(n_samples=1, n_coefficients=3, rms_residual=0.0))
        return self

    def _t0(self, t: FloatArray, T: FloatArray) -> FloatArray:
        inwin = (t - t[0]) < self.window_s
        csum = np.cumsum(T)
        run_mean = csum / np.arange(1, T.size + 1)
        m = int(np.count_nonzero(inwin))
        out = run_mean.copy()
        out[m:] = run_mean[m - 1]
        return out

    def predict(self, run: RunData, *, extrapolate: bool = False) -> FloatArray:
        T = self.clamp(run.temps_c, extrapolate=extrapolate)
        rate = temperature_rate(run.time_s, T[:, 0], self.rate_interval_s, "backward")
        t0 = self._t0(run.time_s, T[:, 0])
        y: FloatArray = self.a * (T[:, 0] - t0) + self.b * rate + self.c * T[:, 1] ** 2
        return y

    def stream(self, sample_interval_s: float, *, extrapolate: bool = False) -> ModelStream:
        return _ToyStream(self, sample_interval_s, extrapolate)

    def coefficients(self) -> list[Coefficient]:
        return [Coefficient("a", self.a), Coefficient("b", self.b), Coefficient("c", self.c)]

    def _state(self) -> dict[str, Any]:
        return {}

    def _set_state(self, state: dict[str, Any]) -> None:
        pass


class _ToyStream(ModelStream):
    def __init__(self, m: ToyModel, tau: float, extrapolate: bool) -> None:
        self.m = m
        self.tau = tau
        self.extrapolate = extrapolate
        self.reset()

    def reset(self) -> None:
        self.t_start: float | None = None
        self.sum = 0.0
        self.n = 0
        self.frozen = False
        self.buf_t: list[float] = []
        self.buf_T: list[float] = []

    def update(self, time_s: float, temps_c: FloatArray, signal: float | None = None) -> float:
        T = self.m.clamp(np.asarray(temps_c).reshape(1, -1), extrapolate=self.extrapolate)[0]
        if self.t_start is None:
            self.t_start = time_s
        if not self.frozen:
            if time_s - self.t_start < self.m.window_s:
                self.sum += T[0]
                self.n += 1
            else:
                self.frozen = True
        t0 = self.sum / self.n
        if self.buf_t and time_s - self.buf_t[-1] > GAP_FACTOR * self.tau:
            self.buf_t.clear()
            self.buf_T.clear()
        self.buf_t.append(time_s)
        self.buf_T.append(float(T[0]))
        while self.buf_t[0] < time_s - self.m.rate_interval_s:
            self.buf_t.pop(0)
            self.buf_T.pop(0)
        span = time_s - self.buf_t[0]
        rate = (T[0] - self.buf_T[0]) / span * 60.0 if span > 0 else 0.0
        return float(self.m.a * (T[0] - t0) + self.m.b * rate + self.m.c * T[1] ** 2)


def _toy_run(n: int = 3000, tau: float = 1.0, gap_at: int | None = 1700, seed: int = 3) -> RunData:
    rng = np.random.default_rng(seed)
    t = np.arange(n) * tau
    if gap_at is not None:
        t[gap_at:] += 137.0
    T1 = 20.0 + 10.0 * np.sin(t / 700.0) + 0.01 * rng.standard_normal(n)
    T2 = 25.0 + 0.003 * t
    temps = np.column_stack([T1, T2])
    sig = 5.0 + rng.standard_normal(n)
    return RunData(time_s=t, temps_c=temps, signal=sig, temp_names=("T1", "T2"), name="toy")


def _fitted_toy(run: RunData) -> ToyModel:
    m = ToyModel().fit([run])
    m.temp_range_ = np.array([[-100.0, 100.0], [-100.0, 100.0]])
    m.signal_name = "gyro"
    m.signal_unit = "deg/h"
    return m


def test_toy_stream_equals_predict() -> None:
    """Sanity check of the toy itself (the contract every family meets)."""
    run = _toy_run()
    m = _fitted_toy(run)
    y = m.predict(run)
    s = m.stream(1.0)
    ys = np.array([s.update(t, T) for t, T in zip(run.time_s, run.temps_c, strict=True)])
    np.testing.assert_allclose(ys, y, rtol=1e-12, atol=1e-12)


def test_batch_compensation_removes_a_known_line() -> None:
    """A poly model fitted to an exact line y = 0.4 + 0.03 T (no noise): the model values
    are that line and the compensated signal is what was added on top of it, both
    written out here, not computed by the code under test."""
    t = np.arange(500.0)
    T = 10.0 + 0.05 * t
    extra = np.sin(t / 7.0)  # what the temperature model must leave untouched
    fit_run = RunData(t, T[:, None], 0.4 + 0.03 * T, ("T1",), "fit")
    m = make_model("poly", terms="T1", per_run_offset=False).fit([fit_run])
    run = RunData(t, T[:, None], 0.4 + 0.03 * T + extra, ("T1",), "apply")
    res = compensate_run(m, run)
    np.testing.assert_allclose(res.model_value, 0.4 + 0.03 * T, rtol=0, atol=1e-10)
    np.testing.assert_allclose(res.corrected, extra, rtol=0, atol=1e-10)


def test_streaming_compensator_equals_batch_with_gap_and_reset() -> None:
    run = _toy_run()
    m = _fitted_toy(run)
    batch = compensate_run(m, run)
    sc = StreamingCompensator(m, 1.0)
    assert run.signal is not None
    out = np.array(
        [sc.update(t, T, f) for t, T, f in zip(run.time_s, run.temps_c, run.signal, strict=True)]
    )
    np.testing.assert_allclose(out, batch.corrected, rtol=1e-12, atol=1e-12)
    # a reset is a new power-on: the second half alone, streamed after reset, equals predict of it
    sc.reset()
    half = RunData(time_s=run.time_s[1000:], temps_c=run.temps_c[1000:], signal=run.signal[1000:])
    res = sc.process(half.time_s, half.temps_c, half.signal)
    np.testing.assert_allclose(res.corrected, compensate_run(m, half).corrected, rtol=1e-12)


def test_streaming_compensator_refuses_time_going_back() -> None:
    run = _toy_run(n=10, gap_at=None)
    sc = StreamingCompensator(_fitted_toy(run), 1.0)
    sc.update(5.0, [20.0, 25.0], 1.0)
    with pytest.raises(TimestampError, match="does not increase"):
        sc.update(5.0, [20.0, 25.0], 1.0)


@pytest.mark.parametrize("chunk", [7, 45, 256, 1699, 5000])
@pytest.mark.parametrize("use_rule", [True, False])
def test_chunk_predictor_equals_whole_predict(
    chunk: int, use_rule: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Chunks predicted with carried context (or streamed) equal one whole-run predict."""
    run = _toy_run()
    m = _fitted_toy(run)
    if use_rule:
        monkeypatch.setattr(
            type(m), "chunk_context", lambda mm: ChunkContext(mm.window_s, mm.rate_interval_s)
        )
    cp = ChunkPredictor(m)
    assert cp.streams is not use_rule
    assert run.signal is not None
    parts = [
        cp.predict(run.time_s[i : i + chunk], run.temps_c[i : i + chunk], run.signal[i : i + chunk])
        for i in range(0, run.n_samples, chunk)
    ]
    np.testing.assert_allclose(np.concatenate(parts), m.predict(run), rtol=1e-12, atol=1e-12)


def _write_csv(path: Path, run: RunData, unit: str = "deg/h", extra: bool = True) -> None:
    assert run.signal is not None
    df = pd.DataFrame(
        {
            "time": run.time_s,
            "gyro": run.signal,
            "T1": run.temps_c[:, 0],
            "T2": run.temps_c[:, 1],
        }
    )
    if extra:
        df["note"] = "x"
        df["truth"] = np.arange(run.n_samples)
    df.to_csv(path, index=False)
    meta = {"signals": {"gyro": unit}, "temperatures": {"T1": "degC", "T2": "degC"}}
    path.with_name(path.name + ".meta.json").write_text(json.dumps(meta))


@pytest.mark.parametrize("out_ext", ["csv", "parquet"])
def test_compensate_file_chunked_equals_in_memory(
    tmp_path: Path, out_ext: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    run = _toy_run()
    m = _fitted_toy(run)
    monkeypatch.setattr(
        type(m), "chunk_context", lambda mm: ChunkContext(mm.window_s, mm.rate_interval_s)
    )
    src = tmp_path / "in.csv"
    _write_csv(src, run)
    out = tmp_path / f"out.{out_ext}"
    res = compensate_file(m, src, out, ReadOptions(time_unit="s"), chunk_rows=333)
    assert res.n_rows == run.n_samples
    assert res.n_chunks == math.ceil(run.n_samples / 333)
    assert not res.streamed
    df = (
        pd.read_csv(out, **csv_float_options())
        if out_ext == "csv"
        else pq.read_table(out).to_pandas()
    )
    assert list(df.columns) == [
        "time",
        "gyro",
        "T1",
        "T2",
        "note",
        "truth",
        "gyro_model",
        "gyro_comp",
    ]
    expect = compensate_run(m, run)
    np.testing.assert_allclose(df["gyro_model"], expect.model_value, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(df["gyro_comp"], expect.corrected, rtol=1e-12, atol=1e-12)
    # input columns kept exactly
    np.testing.assert_array_equal(df["gyro"].to_numpy(), run.signal)
    np.testing.assert_array_equal(df["truth"].to_numpy(), np.arange(run.n_samples))
    assert (df["note"] == "x").all()
    assert run.signal is not None
    assert res.rms_before == pytest.approx(float(np.std(run.signal)), rel=1e-10)
    assert res.rms_after == pytest.approx(float(np.std(expect.corrected)), rel=1e-10)
    if out_ext == "csv":
        side = json.loads((tmp_path / "out.csv.meta.json").read_text())
        assert side["units"]["gyro_comp"] == "deg/h"


def test_compensate_file_streams_unknown_family_parquet_in(tmp_path: Path) -> None:
    run = _toy_run(n=900, gap_at=400)
    m = _fitted_toy(run)
    assert run.signal is not None
    df = pd.DataFrame(
        {"time": run.time_s, "gyro": run.signal, "T1": run.temps_c[:, 0], "T2": run.temps_c[:, 1]}
    )
    src = tmp_path / "in.parquet"
    df.to_parquet(src)
    res = compensate_file(
        m, src, tmp_path / "o.parquet", ReadOptions(time_unit="s"), chunk_rows=100
    )
    assert res.streamed
    got = pq.read_table(tmp_path / "o.parquet").to_pandas()
    np.testing.assert_allclose(got["gyro_comp"], compensate_run(m, run).corrected, rtol=1e-12)


def test_compensate_file_converts_units(tmp_path: Path) -> None:
    """Data in °/s, model in °/h: the added columns are in °/s and equal the °/h result / 3600."""
    run = _toy_run(n=500, gap_at=None)
    m = _fitted_toy(run)
    assert run.signal is not None
    ds = RunData(
        time_s=run.time_s,
        temps_c=run.temps_c,
        signal=run.signal * units.DH_TO_DS,
        temp_names=run.temp_names,
    )
    src = tmp_path / "in.csv"
    _write_csv(src, ds, unit="deg/s", extra=False)
    compensate_file(m, src, tmp_path / "o.csv", ReadOptions(time_unit="s"))
    got = pd.read_csv(tmp_path / "o.csv")
    exp = compensate_run(m, run)
    np.testing.assert_allclose(got["gyro_model"], exp.model_value * units.DH_TO_DS, rtol=1e-12)
    np.testing.assert_allclose(got["gyro_comp"], exp.corrected * units.DH_TO_DS, rtol=1e-12)


def test_unit_mismatch_names_both(tmp_path: Path) -> None:
    run = _toy_run(n=50, gap_at=None)
    m = _fitted_toy(run)
    src = tmp_path / "in.csv"
    _write_csv(src, run, unit="mg", extra=False)
    with pytest.raises(UnitError, match=r"'deg/h'.*'mg'"):
        compensate_file(m, src, tmp_path / "o.csv", ReadOptions(time_unit="s"))
    assert not (tmp_path / "o.csv").exists()
    assert unit_factor("rad/s", "deg/h") == pytest.approx(units.RS_TO_DH, rel=1e-15)


def test_missing_temperature_column_names_missing_and_available(tmp_path: Path) -> None:
    run = _toy_run(n=50, gap_at=None)
    m = _fitted_toy(run)
    m.temp_names_ = ("T1", "Tcase")
    src = tmp_path / "in.csv"
    _write_csv(src, run, extra=False)
    with pytest.raises(MissingColumnError, match=r"'Tcase'.*available: 'time', 'gyro', 'T1', 'T2'"):
        compensate_file(m, src, tmp_path / "o.csv", ReadOptions(time_unit="s"))


def test_never_writes_over_input(tmp_path: Path) -> None:
    run = _toy_run(n=50, gap_at=None)
    src = tmp_path / "in.csv"
    _write_csv(src, run, extra=False)
    before = src.read_bytes()
    with pytest.raises(Exception, match="refusing to write over the input"):
        compensate_file(_fitted_toy(run), src, src)
    assert src.read_bytes() == before


def test_one_extrapolation_warning_for_the_file(tmp_path: Path) -> None:
    run = _toy_run(n=400, gap_at=None)
    m = _fitted_toy(run)
    m.temp_range_ = np.array([[-100.0, 25.0], [-100.0, 100.0]])
    n_out = int(np.count_nonzero(run.temps_c[:, 0] > 25.0))
    src = tmp_path / "in.csv"
    _write_csv(src, run, extra=False)
    with pytest.warns(ExtrapolationWarning, match=f"{n_out} samples outside") as rec:
        compensate_file(m, src, tmp_path / "o.csv", ReadOptions(time_unit="s"), chunk_rows=50)
    assert len([w for w in rec if issubclass(w.category, ExtrapolationWarning)]) == 1


# --- every registered family: streaming == batch, chunked == in memory ----------------------


def _families() -> list[str]:
    import thermocal.models  # noqa: F401  (registers the families)

    return sorted(MODEL_REGISTRY)


def test_every_registered_family_declares_its_chunk_context() -> None:
    """No family falls back to the (exact but slow) sample-by-sample default unnoticed."""
    for fam in _families():
        cls = MODEL_REGISTRY[fam]
        assert cls.chunk_context is not TemperatureModel.chunk_context, fam


def _fit_family(fam: str) -> TemperatureModel:
    from thermocal.simulate import SCENARIOS

    if fam == "poly":
        rec, _ = SCENARIOS["rlg-modelling"](1)[0]
        m = make_model("poly").fit([RunData.from_recording(rec, "gyro", ["T1", "T2", "T3", "T4"])])
    elif fam == "piecewise":
        rec, _ = SCENARIOS["fog-slow"](1)[0]
        m = make_model("piecewise").fit([RunData.from_recording(rec, "gyro", ["T1"])])
    elif fam == "warmup":
        res = SCENARIOS["mems-warmup"](1)
        m = make_model("warmup").fit([RunData.from_recording(r, "gyro", ["T1"]) for r, _ in res])
    elif fam == "bank":
        res = SCENARIOS["accel-full-range"](1)
        runs = [
            RunData.from_recording(r, r.signals[0], ["T1"], known_input=tr["input"])
            for r, tr in res
        ]
        m = make_model("bank").fit(runs)
    elif fam == "hyst":
        rec, _ = SCENARIOS["thermal-lag"](1)[0]
        m = make_model("hyst").fit([RunData.from_recording(rec, "gyro", ["T1"])])
    else:  # pragma: no cover - a new family needs a fitter here
        raise AssertionError(f"no fitter for family {fam!r}")
    m.signal_name = "gyro"
    return m


@pytest.fixture(scope="module", params=_families())
def family_model(request: pytest.FixtureRequest) -> TemperatureModel:
    return _fit_family(str(request.param))


def _family_data(m: TemperatureModel, n: int = 4000) -> RunData:
    from thermocal.export.c import exercise_inputs

    rng = {n: [float(a), float(b)] for n, (a, b) in zip(m.temp_names_, m.temp_range_, strict=True)}
    d = {"temperatures": list(m.temp_names_), "range": {"temperature_c": rng}}
    t, T, f = exercise_inputs(d, n, 1.0, seed=2, gap_at=0.3)
    return RunData(time_s=t, temps_c=T, signal=f, temp_names=tuple(m.temp_names_), known_input=0.1)


def test_every_family_streaming_equals_batch(family_model: TemperatureModel) -> None:
    """StreamingCompensator (sample by sample and block by block) equals the batch
    compensation to 1e-12, power-on and a gap included, for every registered family."""
    m = family_model
    run = _family_data(m)
    assert run.signal is not None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ExtrapolationWarning)  # the sweep leaves the range
        batch = compensate_run(m, run)
        sc = StreamingCompensator(m, 1.0, known_input=run.known_input)
        one = sc.process(run.time_s, run.temps_c, run.signal)
        blk = StreamingCompensator(m, 1.0, known_input=run.known_input)
        parts = [
            blk.update_block(run.time_s[a:b], run.temps_c[a:b], run.signal[a:b]).corrected
            for a, b in itertools.pairwise([0, 1, 7, 100, 1201, 1202, 2500, run.n_samples])
        ]
    scale = float(np.max(np.abs(batch.model_value))) or 1.0
    np.testing.assert_allclose(one.corrected, batch.corrected, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(one.model_value, batch.model_value, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(np.concatenate(parts), batch.corrected, rtol=0, atol=1e-12 * scale)


def test_every_family_compensate_run_is_signal_minus_predict(
    family_model: TemperatureModel,
) -> None:
    """``compensate_run`` (fused in the poly block loop) is exactly F − predict(run)."""
    m = family_model
    run = _family_data(m)
    assert run.signal is not None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ExtrapolationWarning)
        batch = compensate_run(m, run)
        y = m.predict(run)
    np.testing.assert_array_equal(batch.model_value, y)
    np.testing.assert_array_equal(batch.corrected, run.signal - y)


# the models were fitted on other data: the absolute error gets worse (issue 25), said aside
@pytest.mark.filterwarnings(
    "ignore:.*makes the absolute error worse:thermocal.errors.ThermocalWarning"
)
def test_every_family_chunked_file_equals_in_memory(
    family_model: TemperatureModel, tmp_path: Path
) -> None:
    m = family_model
    run = _family_data(m)
    assert run.signal is not None
    cols = {"time": run.time_s, "gyro": run.signal}
    cols.update({n: run.temps_c[:, i] for i, n in enumerate(m.temp_names_)})
    src = tmp_path / "in.parquet"
    pd.DataFrame(cols).to_parquet(src)
    with pytest.warns(ExtrapolationWarning):
        res = compensate_file(
            m,
            src,
            tmp_path / "out.csv",
            ReadOptions(time_unit="s"),
            chunk_rows=333,
            known_input=run.known_input,
        )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ExtrapolationWarning)
        batch = compensate_run(m, run)
    assert not res.streamed
    got = pd.read_csv(tmp_path / "out.csv")
    scale = float(np.max(np.abs(batch.model_value))) or 1.0
    np.testing.assert_allclose(got["gyro_model"], batch.model_value, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(got["gyro_comp"], batch.corrected, rtol=0, atol=1e-12 * scale)


def test_block_and_sample_modes_do_not_mix() -> None:
    run = _toy_run(n=20, gap_at=None)
    sc = StreamingCompensator(_fitted_toy(run), 1.0)
    sc.update(0.0, [20.0, 25.0], 1.0)
    with pytest.raises(ThermocalInputError, match="do not mix"):
        sc.update_block([1.0, 2.0], [[20.0, 25.0], [20.0, 25.0]], [1.0, 1.0])
    sc.reset()
    sc.update_block([1.0, 2.0], [[20.0, 25.0], [20.0, 25.0]], [1.0, 1.0])
    with pytest.raises(TimestampError):
        sc.update_block([2.0, 3.0], [[20.0, 25.0], [20.0, 25.0]], [1.0, 1.0])
