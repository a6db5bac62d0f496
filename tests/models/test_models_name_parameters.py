"""The model families' messages name the library's parameters; the command line shows its
options in their place (:func:`thermocal.pipeline.messages.error_text` and
:func:`~thermocal.pipeline.messages.warning_lines`, what ``thermocal fit`` prints)."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal.adequacy import Adequacy
from thermocal.cli import main
from thermocal.errors import DesignError, ThermocalInputError, UnitError
from thermocal.models.breakpoints import segment_tests
from thermocal.models.rundata import RunData, _run_units
from thermocal.models.terms import parse_terms
from thermocal.models.warmup import WarmupModel
from thermocal.pipeline.messages import error_text, warning_lines


def test_a_term_list_and_an_order_name_the_parameter() -> None:
    with pytest.raises(ThermocalInputError) as both:
        parse_terms("T1,T1^2", 1, order=2)
    assert str(both.value) == "give either an explicit term list or order, not both"
    assert error_text(both.value) == (
        "give either an explicit term list or --order, not both",
        True,
    )
    with pytest.raises(ThermocalInputError) as bad:
        parse_terms("X1", 1)
    assert str(bad.value).endswith("(k = position in temperatures, from 1)")
    assert error_text(bad.value)[0].endswith("(k = position in --temps, from 1)")


def _power_on(t_amb: float, seed: int) -> RunData:
    """A power-on at ambient ``t_amb`` (8 min at 1 Hz, self-heating 7 °C)."""
    rng = np.random.default_rng(seed)
    t = np.arange(480, dtype=np.float64)
    temp = t_amb + 7.0 * (1 - np.exp(-t / 100.0)) + rng.normal(0.0, 0.01, t.size)
    sig = 3.0 + 0.2 * (temp - t_amb) + rng.normal(0.0, 0.05, t.size)
    return RunData(time_s=t, temps_c=temp[:, None], signal=sig, temp_names=("T1",), name="p")


def test_warmup_names_t0_order() -> None:
    runs = [_power_on(20.0, i) for i in range(3)]  # one start temperature, three runs
    with pytest.raises(DesignError) as info:
        WarmupModel(order=2, t0_order=1).fit(runs)
    assert str(info.value).endswith("add runs or lower t0_order")
    assert error_text(info.value)[0].endswith("add runs or lower --t0-order")


def test_mixed_temperature_units_name_temp_conversion() -> None:
    run = _power_on(20.0, 0)
    counts = RunData(
        time_s=run.time_s,
        temps_c=run.temps_c,
        signal=run.signal,
        temp_names=("T1",),
        name="raw",
        temperature_unit="counts",
    )
    with pytest.raises(UnitError) as info:
        _run_units([run, counts])
    assert str(info.value).endswith("give temp_conversion for the counts")
    assert error_text(info.value)[0].endswith("give --temp-conversion for the counts")


def test_a_segment_names_segments_or_breakpoints_and_the_fit_command_its_options() -> None:
    # runs over 0…9.9, 10…10.4 and 20…30 °C, breakpoints at 10 and 12 °C: the middle
    # segment 10…12 °C spans 0.4 °C (a line needs 5 °C; allow_narrow overrides)
    xs = [np.linspace(0.0, 9.9, 300), np.linspace(10.0, 10.4, 300), np.linspace(20.0, 30.0, 300)]
    bps = np.array([10.0, 12.0])
    for given, python, cli in (
        (False, "ask fewer segments (segments 2)", "ask fewer --segments (--segments 2)"),
        (True, "move or drop a breakpoint (breakpoints)", "(--breakpoints)"),
    ):
        tests = segment_tests(bps, xs, "T", 0.0, 30.0, given=given)
        middle = next(t for t in tests if t.name == "segment_2_temperature_span")
        assert middle.verdict == "fail" and middle.threshold == 5.0
        assert middle.to_dict()["message"].endswith(python)  # what a model file stores
        with pytest.raises(ThermocalInputError) as info:
            Adequacy(tests, (), "gyro").enforce()
        assert python in str(info.value)
        assert cli in error_text(info.value)[0]
    with warnings.catch_warnings(record=True) as caught:  # fitted anyway: a warning
        warnings.simplefilter("always")
        Adequacy(tests, (str(middle.override),), "gyro").enforce()
    shown = warning_lines(caught)
    assert any("move or drop a breakpoint (--breakpoints) — fitted anyway" in s for s in shown)
    assert all("{" not in str(w.message) for w in caught)


def test_fit_shows_the_option_where_a_warning_names_per_run_offset(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Two runs 20…24 and 40…44 °C: pooled, with the advice the library words as
    ``per_run_offset`` and ``thermocal fit`` as ``--per-run-offset``, on stderr and in
    its ``--json`` result."""
    rng = np.random.default_rng(1)
    files = []
    for name, t0 in (("a", 20.0), ("b", 40.0)):
        t = np.arange(0.0, 3600.0)
        temp = t0 + 4.0 * (1 - np.exp(-t / 600.0))
        gyro = 69.0 * (temp - 25.0) + 2.0 * rng.standard_normal(t.size)
        path = tmp_path / f"{name}.csv"
        pd.DataFrame({"time_s": t, "gyro_dph": gyro, "T1": temp}).to_csv(path, index=False)
        files.append(str(path))
    args = ["--model", "poly", "--order", "1", "--signal", "gyro_dph", "--temps", "T1",
            "--time", "time_s", "--time-unit", "s", "--signal-unit", "deg/h",
            "--temp-unit", "degC"]  # fmt: skip
    code = main(["fit", *files, *args, "-o", str(tmp_path / "m.json"), "--json"])
    out, err = capsys.readouterr()
    assert code == 0
    advice = "Pass --per-run-offset to force offsets"
    assert advice in err
    assert any(advice in w for w in json.loads(out)["warnings"])


def test_raw_counts_without_a_count_scale_name_the_scale_parameter() -> None:
    from types import SimpleNamespace

    from thermocal.models.calibration import Triad

    triad = Triad("gyro", ("gx", "gy", "gz"), "deg/s", "T", SimpleNamespace(kind="gyro"))
    with pytest.raises(UnitError) as info:
        triad.input_in({"counts"}, "held.csv")
    assert str(info.value).endswith("calibrate the counts with multipos gyro_scale VALUE,UNIT")
    text = error_text(info.value)[0]
    assert text.endswith("calibrate the counts with multipos --gyro-scale VALUE,UNIT")
    assert text.startswith("held.csv: the gyro triad's columns are raw counts")
