"""The compensation kernels (:mod:`thermocal.compensate.kernels`) against figures written
out here: the absolute error figures and the rule that calls a model worse, and pulse
counts converted to the model's unit.  Each kills a mutant of
``benchmarks/mutation_check.py``."""

from __future__ import annotations

import numpy as np
import pytest


def test_absolute_figures_and_the_worse_rule_by_hand() -> None:
    """Errors 3 and 4 about zero: mean 3.5, rms √12.5, max 4 (mutant
    compensate-abs-rms-about-mean gives the σ 0.5); an rms about zero 1.0 → 1.2 is worse
    beyond the tolerance, 1.0 → 1.0 + tolerance/2 is not (mutant compensate-worse-strict
    needs 10× the tolerance)."""
    from thermocal.compensate.kernels import (
        ABSOLUTE_WORSE_TOLERANCE,
        AbsoluteFigures,
        absolute_error_worse,
        absolute_figures,
    )

    f = absolute_figures([3.0, 4.0])
    assert (f.mean, f.max_abs) == (3.5, 4.0)
    assert f.rms_about_zero == pytest.approx(np.sqrt(12.5), rel=1e-15)
    tol = ABSOLUTE_WORSE_TOLERANCE
    assert 0.0 < tol < 0.1
    before = AbsoluteFigures(0.0, 1.0, 2.0)
    assert absolute_error_worse(before, AbsoluteFigures(0.0, 1.0 + 2.0 * tol, 2.0)) == [
        "rms about zero"
    ]
    assert absolute_error_worse(before, AbsoluteFigures(0.0, 1.0 + 0.5 * tol, 2.0)) == []


def test_counts_to_a_model_in_degrees_per_second() -> None:
    """Pulse counts with K = 2 pulses/″ at τ = 0.5 s: one count is 1/(0.5·2) = 1 ″/s =
    1 °/h = 1/3600 °/s; the factor to a model in °/s is 1/3600 (mutant
    compensate-counts-tau-default gives 3600)."""
    from thermocal.compensate.kernels import unit_factor
    from thermocal.recording import Metadata

    meta = Metadata(scale_factor=2.0, scale_factor_unit="counts/arcsec")
    f = unit_factor("counts", "deg/s", meta=meta, sample_interval_s=0.5)
    assert f == pytest.approx(1.0 / 3600.0, rel=1e-12)
