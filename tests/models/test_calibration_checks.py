"""A calibration's reader checks applied before it is written (:mod:`thermocal.models.calibration`,
:mod:`thermocal.models.checks`): a TREF the reader refuses, a triad whose ``I + E`` the
reader refuses, every writer.  Each kills a mutant of ``benchmarks/mutation_check.py``
(``h39mp-…``) against a reference from outside the code under test."""

from __future__ import annotations

import numpy as np
import pytest

from thermocal.errors import DesignError, ThermocalInputError
from thermocal.pipeline.messages import error_text
from thermocal.turntable import thermal


def test_a_tref_the_reader_refuses_is_refused_before_the_fit() -> None:
    """The reader accepts a TREF within the soaks' range or ``max(span, 50 °C)`` of it
    (:func:`thermocal.models.checks.range_margin`); soaks at −10, 20, 50 °C: span 60, so
    −70 … 110 °C.  110 is fitted, 110.5 refused naming
    ``tref_c`` (``--tref`` on the command line; 1e9 too)."""
    temps = [-10.0, 20.0, 50.0]
    th = np.zeros((3, 12))
    sg = np.ones((3, 12))
    assert thermal.fit_triad("accel", temps, th, sg, tref_c=110.0).tref_c == 110.0
    assert thermal.fit_triad("accel", temps, th, sg, tref_c=-70.0).tref_c == -70.0
    for bad in (110.5, -70.5, 1e9, float("nan")):
        with pytest.raises(ThermocalInputError, match=r"^tref_c ") as err:
            thermal.fit_triad("accel", temps, th, sg, tref_c=bad)
        assert error_text(err.value)[0].startswith("--tref ")  # the command line's option


def test_a_calibration_its_reader_refuses_is_not_written(tmp_path: object) -> None:
    """A triad whose ``I + E`` has condition number 20 (x scale factor −95 %: singular
    values 1 and 0.05, computed here) is refused by the reader (≤ 10); it is refused
    before the write, naming the condition number, and nothing is written."""
    from pathlib import Path

    from thermocal.models.calibration import Calibration, Triad
    from thermocal.pipeline.turntable import check_as_read

    th = np.zeros(12)
    th[3] = -0.95e6  # ppm
    sv = np.linalg.svd(np.diag([0.05, 1.0, 1.0]), compute_uv=False)
    assert sv[0] / sv[-1] == pytest.approx(20.0)
    m = thermal.constant_triad("accel", 25.0, th, np.eye(12), method="multipos")
    cal = Calibration([], [Triad("accel", ("ax", "ay", "az"), "mg", "", m)])
    out = Path(str(tmp_path)) / "cal.json"
    with pytest.raises(DesignError, match=r"condition number 20"):
        check_as_read(cal, out, "the hint")
    assert not out.exists()
    th[3] = -0.85e6  # condition 1/0.15 = 6.7: accepted by the reader, and here
    ok = thermal.constant_triad("accel", 25.0, th, np.eye(12), method="multipos")
    check_as_read(Calibration([], [Triad("accel", ("ax", "ay", "az"), "mg", "", ok)]), out, "")


def test_every_calibration_writer_applies_the_readers_checks(tmp_path: object) -> None:
    """``save_calibration`` (fit, tempcal, multipos, turntable, the demo all write through
    it): the condition-20 triad above is refused, nothing written; a TREF 200 °C beyond a
    25 °C-only range (the reader's margin is 50 °C) too."""
    from pathlib import Path

    from thermocal.models.calibration import Calibration, Triad
    from thermocal.pipeline.model_file import save_calibration

    out = Path(str(tmp_path)) / "cal.json"
    th = np.zeros(12)
    th[3] = -0.95e6
    bad = thermal.constant_triad("accel", 25.0, th, np.eye(12), method="multipos")
    with pytest.raises(DesignError, match=r"condition number 20.*not written"):
        save_calibration(Calibration([], [Triad("accel", ("ax", "ay", "az"), "mg", "", bad)]), out)
    assert not out.exists()
    far = thermal.constant_triad("accel", 200.0, np.zeros(12), np.eye(12), t_range_c=(25.0, 25.0))
    with pytest.raises(DesignError, match=r"TREF 200"):
        save_calibration(Calibration([], [Triad("accel", ("ax", "ay", "az"), "mg", "", far)]), out)
    assert not out.exists()
