"""The simulator's sample budget names the parameters that lower it (``rate_hz``,
``profile``, ``record_s``, ``runs``); the ``simulate`` command shows its own spelling
(``--rate-hz``, where ``fit`` spells a rate ``--rate``)."""

from __future__ import annotations

import pytest

from thermocal.defaults import MAX_SIMULATED_SAMPLES
from thermocal.errors import ThermocalInputError
from thermocal.pipeline.messages import error_text
from thermocal.simulate.scenarios import check_sample_budget


def test_the_sample_budget_names_parameters_and_the_command_its_options() -> None:
    n = 2.0 * MAX_SIMULATED_SAMPLES
    with pytest.raises(ThermocalInputError) as caught:
        check_sample_budget(n, "x")
    assert str(caught.value) == (
        f"x: {n:.3g} samples to simulate, above the limit of {MAX_SIMULATED_SAMPLES:.3g}: "
        "lower rate_hz, or shorten the chamber program (profile, record_s, runs)"
    )
    shown = error_text(caught.value, {"rate_hz": "--rate-hz"})[0]
    assert shown.endswith(
        "lower --rate-hz, or shorten the chamber program (--profile, --record-s, --runs)"
    )
    check_sample_budget(float(MAX_SIMULATED_SAMPLES), "x")  # the limit itself is allowed
