"""The stability analysis names its parameters; the command line shows its options there.

A Python user of :mod:`thermocal.stability` reads ``dynamic_s``, ``deviations``, ``taus``,
``max_work``, ``confidence``, ``inflate``; the ``allan`` and ``noise`` commands show
``--dynamic``, ``--deviation``, ``--taus``, ``--max-work``, ``--confidence``, ``--inflate``
in the same place (:func:`thermocal.pipeline.messages.error_text` and
:func:`~thermocal.pipeline.messages.warning_lines`, the mapping the command line uses).
Every count in the messages (windows, τ) is computed here from its definition.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from thermocal.errors import ConditioningWarning, ParameterError, ThermocalInputError
from thermocal.pipeline.messages import error_text, warning_lines
from thermocal.recording import Recording
from thermocal.stability.allan import check_dynamic_work, dynamic_adev, overlapping_adev
from thermocal.stability.analysis import allan_analysis, check_not_stuck, check_tau_list
from thermocal.stability.edf import check_confidence
from thermocal.stability.noise_model import axis_noise, noise_model


def _recording(n: int) -> Recording:
    rng = np.random.default_rng(0)
    return Recording.from_arrays(np.arange(n, dtype=np.float64), {"gx": rng.normal(0, 1, n)})


def test_the_dynamic_window_budget_names_dynamic_s_and_max_work() -> None:
    """Windows of 8 samples half a window apart on 1e5 samples: (1e5 − 8) // 4 + 1."""
    windows = (100_000 - 8) // 4 + 1
    with pytest.raises(ThermocalInputError) as caught:
        allan_analysis(_recording(100_000), ["gx"], dynamic_s=8.0, max_work=1e9, where="f.csv")
    text = str(caught.value)
    assert text.startswith(f"f.csv: dynamic_s 8 s on 100000 samples makes {windows} windows")
    assert "raise max_work to " in text and "--" not in text
    shown, user = error_text(caught.value)
    assert user and shown.startswith(f"f.csv: --dynamic 8 s on 100000 samples makes {windows}")
    assert "raise --max-work to " in shown


def test_the_dynamic_adev_names_the_callers_window_parameter() -> None:
    """Called alone it names its own ``window_s``; a 4 s window at τ0 = 1 s is 4 samples."""
    y = np.random.default_rng(1).normal(0.0, 1.0, 1000)
    whole = overlapping_adev(y, 1.0)
    with pytest.raises(ParameterError, match=r"^window_s 4 s holds 4 samples at τ0 = 1 s"):
        dynamic_adev(y, 1.0, 4.0, whole)
    with pytest.raises(ParameterError) as caught:
        dynamic_adev(y, 1.0, 4.0, whole, parameter="dynamic_s")
    assert error_text(caught.value)[0].startswith("--dynamic 4 s holds 4 samples")
    with pytest.raises(ParameterError, match=r"^max_work -1\.0: give a positive operation"):
        check_dynamic_work(1000, 1.0, 8.0, -1.0)


def test_the_family_budget_names_deviations_taus_and_max_work() -> None:
    with pytest.raises(ThermocalInputError) as caught:
        allan_analysis(_recording(4096), ["gx"], deviations=["totdev"], taus="all", max_work=1e3)
    text = str(caught.value)
    assert text.startswith("deviations totdev at taus all on 4097 points needs about ")
    assert "use taus octave or fewer deviations, or raise max_work to " in text
    shown = error_text(caught.value)[0]
    assert shown.startswith("--deviation totdev at --taus all on 4097 points needs about ")
    assert "use --taus octave or fewer deviations, or raise --max-work to " in shown


def test_the_family_only_parameters_and_the_dynamic_adev_name_parameters() -> None:
    rec = _recording(4096)
    with pytest.raises(ThermocalInputError) as caught:
        allan_analysis(rec, ["gx"], bias_correct=True, noise_type=0)
    assert str(caught.value) == (
        "bias_correct (totdev, htotdev), noise_type: for the deviation family's intervals; "
        "give the deviations with deviations (the overlapping ADEV: deviations oadev)"
    )
    assert error_text(caught.value)[0] == (
        "--bias-correct (totdev, htotdev), --noise-type: for the deviation family's "
        "intervals; give the deviations with --deviation (the overlapping ADEV: "
        "--deviation oadev)"
    )
    with pytest.raises(ThermocalInputError) as caught:
        allan_analysis(rec, ["gx"], data_type="phase", dynamic_s=100.0)
    assert str(caught.value) == (
        "dynamic_s computes the overlapping ADEV of rate data; run it without deviations "
        "and data_type phase"
    )
    assert error_text(caught.value)[0] == (
        "--dynamic computes the overlapping ADEV of rate data; run it without --deviation "
        "and --data-type phase"
    )


def test_confidence_inflate_and_a_stuck_column_name_parameters() -> None:
    with pytest.raises(ParameterError) as caught:
        check_confidence(0.0)
    assert caught.value.parameter == "confidence"
    assert str(caught.value).startswith("confidence 0.0: give a confidence level between")
    assert error_text(caught.value)[0].startswith("--confidence 0.0: give a confidence")
    ax = axis_noise(np.random.default_rng(2).normal(0, 1e-3, 4000), 0.01, name="gx",
                    sensor="gyro", unit="rad/s")  # fmt: skip
    with pytest.raises(ParameterError) as caught:
        noise_model([ax], 100.0, inflate=0.5)
    assert str(caught.value) == "inflate 0.5: give a factor ≥ 1 (1: none)"
    assert error_text(caught.value)[0] == "--inflate 0.5: give a factor ≥ 1 (1: none)"
    with pytest.raises(ThermocalInputError) as caught:
        check_not_stuck(np.full(20, 3.0), "gx", "f.csv", "gyro")
    assert str(caught.value).endswith("name another column with gyro, or check the sensor")
    assert error_text(caught.value)[0].endswith("with --gyro, or check the sensor")


def test_a_tau_list_names_taus() -> None:
    """4096 rate samples every 0.5 s: the overlapping ADEV reaches m ≤ (4096 − 1) // 2,
    τ ≤ 1023.5 s; 1e6 s lies outside, 1 s inside."""
    with pytest.raises(ThermocalInputError) as caught:
        check_tau_list([1e6], 0.5, 4096, ["adev-rate"], "f.csv")
    assert str(caught.value).startswith("f.csv: taus 1e+06: no τ within the record")
    assert "1023.5 s" in str(caught.value) and "give taus in that range" in str(caught.value)
    assert error_text(caught.value)[0].startswith("f.csv: --taus 1e+06: no τ within the record")
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        check_tau_list([1.0, 1e6], 0.5, 4096, ["adev-rate"], "f.csv")
    assert [w.category for w in seen] == [ConditioningWarning]
    assert str(seen[0].message).startswith("f.csv: taus: τ 1e+06 s left out")
    assert warning_lines(seen)[0].startswith("f.csv: --taus: τ 1e+06 s left out")
