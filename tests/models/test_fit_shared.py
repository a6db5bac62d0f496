"""Several channels sharing one design (issue 15): :func:`fit_shared` does the temperature
work once and gives every channel exactly — bit for bit — the model a fit of that channel
alone gives, on every solver path, with term selection and with per-run offsets."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from thermocal.errors import ExtrapolationWarning, ThermocalInputError
from thermocal.models.poly import PolyModel
from thermocal.models.poly_fit import fit_shared
from thermocal.models.rundata import RunData


def _runs(seed: int, n: int = 6000) -> list[RunData]:
    """Two runs at separate temperatures (offsets are then estimable per run only when the
    runs overlap: the second run overlaps the first here)."""
    rng = np.random.default_rng(seed)
    out = []
    for r, (lo, hi) in enumerate(((-10.0, 50.0), (-5.0, 60.0))):
        t = np.arange(n, dtype=np.float64)
        T = lo + (hi - lo) * (0.5 - 0.5 * np.cos(2 * np.pi * t / n))
        temps = np.column_stack([T, np.interp(t - 300.0, t, T)])
        y = 0.5 * T + 1e-3 * T**2 + 0.02 * rng.standard_normal(n) + 0.3 * r
        out.append(RunData(t, temps, y, ("T1", "T2"), f"run{r}"))
    return out


def _channels(base: list[RunData]) -> list[list[RunData]]:
    """Four channels on the same runs: other slopes, a known input, a duplicate."""
    rng = np.random.default_rng(9)
    chans = [base]
    for j in range(1, 3):
        chans.append([
            dataclasses.replace(
                r, signal=-0.7 * j * r.temps_c[:, 1] + 0.05 * rng.standard_normal(r.n_samples),
                known_input=100.0 * j,
            )
            for r in base
        ])  # fmt: skip
    chans.append([dataclasses.replace(r, signal=r.signal.copy()) for r in base])
    return chans


@pytest.mark.parametrize(
    "params",
    [
        {"order": 2},
        {"order": 2, "solver": "qr"},
        {"terms": "seed000"},
        {"order": 3, "select": "bic"},
        {"order": 3, "select": "holdout"},
        {"order": 2, "per_run_offset": True},
        {"order": 2, "ridge": 1e-3},
    ],
)
def test_each_channel_equals_its_own_fit_bit_for_bit(params: dict) -> None:
    chans = _channels(_runs(1))
    alone = [PolyModel(**params).fit(runs) for runs in chans]
    shared = [PolyModel(**params) for _ in chans]
    fit_shared(shared, chans)
    for a, b in zip(alone, shared, strict=True):
        assert a.constant_ == b.constant_
        assert np.array_equal(a.coef_, b.coef_)
        assert np.array_equal(a.offsets_, b.offsets_)
        assert np.array_equal(a.cov_, b.cov_)
        assert [t.name for t in a.terms_] == [t.name for t in b.terms_]
        assert a.stats_.rms_residual == b.stats_.rms_residual
        assert a.stats_.to_dict() == b.stats_.to_dict()
        assert np.array_equal(a.temp_range_, b.temp_range_)


def test_the_channels_differ_where_their_data_do() -> None:
    chans = _channels(_runs(2))
    models = [PolyModel(order=2) for _ in chans]
    fit_shared(models, chans)
    slopes = [{c.name: c.value for c in m.coefficients()}["T2"] for m in models[1:3]]
    assert slopes[0] == pytest.approx(-0.7, rel=0.02)
    assert slopes[1] == pytest.approx(-1.4, rel=0.02)


def test_runs_that_differ_in_temperature_are_refused() -> None:
    base = _runs(3)
    other = [dataclasses.replace(r, temps_c=r.temps_c + 0.1) for r in base]
    with pytest.raises(ThermocalInputError, match="differ in time or temperatures"):
        fit_shared([PolyModel(order=2), PolyModel(order=2)], [base, other])


def test_models_with_other_parameters_are_refused() -> None:
    base = _runs(4)
    with pytest.raises(ThermocalInputError, match="parameters differ"):
        fit_shared([PolyModel(order=2), PolyModel(order=3)], [base, base])


@pytest.mark.parametrize(
    "params", [{"terms": "seed000"}, {"order": 3}, {"order": 2, "rate_method": "centred"}]
)
def test_predict_many_equals_each_predict_with_gaps_and_clamping(params: dict) -> None:
    from thermocal.models.poly_eval import evaluation_key, predict_many

    chans = _channels(_runs(5))
    models = [PolyModel(**params) for _ in chans]
    fit_shared(models, chans)
    assert len({evaluation_key(m) for m in models}) == 1
    # another run: beyond the fitted range at both ends, with a gap
    t = np.r_[np.arange(3000.0), 5000.0 + np.arange(3000.0)]
    T1 = np.linspace(-30.0, 80.0, t.size)
    run = RunData(t, np.column_stack([T1, T1 - 1.0]), None, ("T1", "T2"), "other")
    with pytest.warns(ExtrapolationWarning):
        got = predict_many(models, run)
    for m, y in zip(models, got, strict=True):
        with pytest.warns(ExtrapolationWarning):
            assert np.array_equal(y, m.predict(run))


def test_predict_many_evaluates_models_of_other_structure_one_by_one() -> None:
    from thermocal.models.poly_eval import predict_many

    base = _runs(6)
    a, b = PolyModel(order=2).fit(base), PolyModel(order=3).fit(base)
    got = predict_many([a, b], base[0])
    assert np.array_equal(got[0], a.predict(base[0]))
    assert np.array_equal(got[1], b.predict(base[0]))
