"""The firmware-learning tutorial (``docs/tutorials/firmware-learning.md``) runs as written:
both commands in an empty folder, what they print equal to the page's ``text`` blocks, and
the page's claims checked on the files they wrote: ArduPilot's learning stops short of
``INS_TCAL1_TMAX`` 70 °C on a sweep to 50 °C, PX4's ends after a rise of more than
``SYS_CAL_TDEL`` 24 °C from its start at ``SYS_CAL_TMIN`` 5 °C (make_fc_logs.py: −10 → 50 °C
over 3000 s at 1 Hz)."""

from __future__ import annotations

from pathlib import Path

import pytest

from tutorial_pages import ROOT, _numbers, _run_in_scratch

PAGE = "firmware-learning.md"


@pytest.fixture(scope="module")
def page(tmp_path_factory: pytest.TempPathFactory) -> tuple[list[tuple[str, str]], Path]:
    tmp = tmp_path_factory.mktemp("learning")
    (tmp / "docs").symlink_to(ROOT / "docs", target_is_directory=True)
    return _run_in_scratch(tmp, PAGE), tmp


def test_learning_tutorial_prints_what_the_page_shows(
    page: tuple[list[tuple[str, str]], Path],
) -> None:
    pairs, _ = page
    assert len(pairs) == 2
    for printed, shown in pairs:
        assert _numbers(printed) == _numbers(shown)
        # stripped both sides: rich versions pad a table's title differently (centred with
        # leading spaces on the floor's rich, flush on the lock's)
        lines = [ln.strip() for ln in printed.strip().splitlines()]
        assert lines == [ln.strip() for ln in shown.strip().splitlines()]


def test_learning_tutorial_claims(page: tuple[list[tuple[str, str]], Path]) -> None:
    """PX4's start is the sweep's first sample at or above 5 °C (reached ~1000 s after
    boot, long past the 10 s wait), its end the first sample more than 24 °C above it:
    both computed here from make_fc_logs.py's temperature."""
    import importlib.util

    import numpy as np

    pairs, _tmp = page
    ap, px4 = (printed for printed, _shown in pairs)
    assert "not completed: the temperature reached" in ap and "INS_TCAL1_TMAX 70.0" in ap
    spec = importlib.util.spec_from_file_location(
        "make_fc_logs", ROOT / "docs" / "tutorials" / "data" / "make_fc_logs.py"
    )
    assert spec is not None and spec.loader is not None
    make = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(make)
    _t, temp, _g, _a = make.truth()
    temp = temp.astype(np.float32)
    low = temp[np.argmax(temp >= np.float32(5.0))]
    high = temp[np.argmax(temp - low > np.float32(24.0))]
    line = next(ln for ln in px4.splitlines() if ln.startswith("sensor_gyro.0 on-board"))
    assert f"rose {float(high - low):.2f} °C" in line and f"from {float(low):.1f} °C" in line
