"""Validation (:mod:`thermocal.validation`) against figures written out here: a run that repeats
the modelling run, the ambient column, every figure in the data's unit.  Each kills a
mutant of ``benchmarks/mutation_check.py`` (``h39mp-…``)."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest


def _validation_inputs() -> tuple[Any, Any, Any]:
    from test_validation import _synthetic_run

    return _synthetic_run()


@pytest.mark.filterwarnings("ignore::thermocal.errors.ThermocalWarning")
def test_a_run_that_repeats_the_modelling_run_is_not_judged_improved() -> None:
    """SPEC §5: a validation run whose ambient repeats the modelling run's (r = 1 ≥ 0.4)
    proves nothing: its verdict says so, whatever the figures."""
    from thermocal.validation import validate

    run, _noise, model = _validation_inputs()
    res = validate(model, run, (run.time_s, run.temps_c[:, 0]))
    assert res.r == pytest.approx(1.0, abs=1e-12)
    assert res.verdict == "NOT weakly correlated"
    assert res.to_dict()["verdict"] == "NOT weakly correlated"


@pytest.mark.filterwarnings("ignore::thermocal.errors.ThermocalWarning")
def test_the_ambient_is_the_first_temperature_column() -> None:
    """A run with a second temperature column held at 25 °C: the ambient (stages, r) is the
    first column: four holds (the profile's), and r equals numpy's Pearson r of the first
    column against the modelling history on their common time base, computed here."""
    from test_validation import _profile
    from thermocal.models.rundata import RunData
    from thermocal.profiles import common_base
    from thermocal.validation import validate

    run, _noise, model = _validation_inputs()
    two = RunData(time_s=run.time_s, temps_c=np.column_stack([run.temps_c[:, 0],
                  np.full(run.time_s.size, 25.0)]), signal=run.signal,
                  temp_names=("T1", "T_board"), name="two")  # fmt: skip
    t_mod, temp_mod = _profile((30.0, 0.0, 10.0, 50.0))
    res = validate(model, two, (t_mod, temp_mod), averaging_s=100.0)
    assert res.n_stages == 4
    _b, x, y = common_base(t_mod, temp_mod, run.time_s, run.temps_c[:, 0])
    assert res.r == pytest.approx(float(np.corrcoef(x, y)[0, 1]), abs=1e-12)


@pytest.mark.filterwarnings("ignore::thermocal.errors.ThermocalWarning")
def test_figures_shown_in_the_datas_unit_are_all_converted() -> None:
    """Shown in °/s (1 °/s = 3600 °/h): each stage's bias stability (the std of its
    100-sample block means, computed here) and the zero reference (15.04 °/h, an earth
    rate) divided by 3600, as the run's own figures are."""
    from thermocal.validation import validate

    run, _noise, model = _validation_inputs()
    t_mod = run.time_s
    res = validate(model, run, (t_mod, run.temps_c[::-1, 0]), averaging_s=100.0,
                   zero_reference=(15.04, "earth rate"))  # fmt: skip
    shown = res.in_unit("deg/s", 3600.0)
    assert shown.zero_reference == pytest.approx(15.04 / 3600.0, rel=1e-12)
    assert shown.to_dict()["zero_reference"]["value"] == pytest.approx(15.04 / 3600.0)
    sig = np.asarray(run.signal)
    for s in shown.stages:
        a = int(np.searchsorted(run.time_s, s.start_s))
        b = int(np.searchsorted(run.time_s, s.stop_s)) + 1
        k = (b - a) // 100
        blocks = sig[a : a + 100 * k].reshape(k, 100).mean(axis=1)
        assert s.bias_stability_before == pytest.approx(np.std(blocks, ddof=1) / 3600.0,
                                                        rel=1e-9)  # fmt: skip
        assert s.bias_before == pytest.approx(sig[a:b].mean() / 3600.0, rel=1e-9)
    assert shown.bias_stability_before == pytest.approx(res.bias_stability_before / 3600.0)
