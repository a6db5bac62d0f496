"""C export edge cases a mutation check found unguarded (issue 12 §5): a piecewise model
that jumps at its breakpoint, evaluated exactly there, and the rate buffer's gap test
under timestamp jitter (real loggers never sample perfectly regularly)."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from thermocal.compensate.kernels import StreamingCompensator
from thermocal.export.c import compile_harness, find_compiler, generate_c, run_harness
from thermocal.models.registry import make_model
from thermocal.models.rundata import RunData
from thermocal.pipeline.model_file import load_model, load_model_dict, save_model

pytestmark = pytest.mark.skipif(find_compiler() is None, reason="no C compiler")


def test_discontinuous_piecewise_takes_the_upper_line_at_the_breakpoint(tmp_path: Path) -> None:
    """y = A[j] + S[j]·T with j = number of breakpoints ≤ T (models/piecewise.py eq. 1):
    at T = 25 °C exactly the second line applies.  The lines are made to jump by 0.5 at
    25 °C, so taking the lower line there (BP < T instead of BP ≤ T) shows."""
    T = np.linspace(10.0, 40.0, 3000)
    run = RunData(np.arange(3000.0), T[:, None], 0.1 * T, ("T1",), "r")
    m = make_model("piecewise", breakpoints=[25.0], method="continuous").fit([run])
    m.intercepts_ = np.array([1.0, 1.5])  # a 0.5 jump at the breakpoint
    m.slopes_ = np.array([0.1, 0.1])
    m.breakpoints_ = np.array([25.0])
    m.signal_name = "gyro"
    save_model(m, tmp_path / "pw.json")
    d = load_model_dict(tmp_path / "pw.json")
    temps = np.array([24.0, np.nextafter(25.0, 0.0), 25.0, 26.0])
    exe = compile_harness(generate_c(d, prefix="jump"), tmp_path / "c")
    y_c = run_harness(exe, np.arange(4.0), temps[:, None], np.zeros(4), 1.0)
    expect = np.array([1.0 + 2.4, 1.0 + 0.1 * np.nextafter(25.0, 0.0), 1.5 + 2.5, 1.5 + 2.6])
    np.testing.assert_allclose(y_c, expect, rtol=0.0, atol=1e-12)
    py = load_model(tmp_path / "pw.json").predict(
        RunData(np.arange(4.0), temps[:, None], np.zeros(4), ("T1",), "p")
    )
    np.testing.assert_allclose(py, expect, rtol=0.0, atol=1e-12)


def test_rate_terms_with_jittered_timestamps_match_python(tmp_path: Path) -> None:
    """Sample steps of τ·(1 ± 30 %): none is a gap (GAP_FACTOR = 1.5), so neither the
    Python stream nor the C may reset its Ṫ buffer; a C that tested steps against τ
    alone would reset at every long step and differ."""
    rng = np.random.default_rng(9)
    n = 6000
    t = np.cumsum(1.0 + rng.uniform(-0.3, 0.3, n))
    T1 = 20.0 + 15.0 * np.sin(2 * np.pi * t / 3000.0)
    y = 0.02 * T1 + 0.5 * np.gradient(T1, t) * 60.0 + 1e-3 * rng.standard_normal(n)
    run = RunData(t, T1[:, None], y, ("T1",), "jitter")
    m = make_model("poly", terms="T1,dT1", rate_interval_s=30.0).fit([run])
    m.signal_name = "gyro"
    save_model(m, tmp_path / "m.json")
    d = load_model_dict(tmp_path / "m.json")
    exe = compile_harness(generate_c(d, prefix="jit", sample_interval_s=1.0), tmp_path / "c")
    y_c = run_harness(exe, t, T1[:, None], y, 1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        py = StreamingCompensator(load_model(tmp_path / "m.json"), 1.0).process(t, T1[:, None], y)
    scale = float(np.max(np.abs(py.model_value)))
    assert float(np.max(np.abs(y_c - py.model_value))) <= 1e-9 * scale
    assert float(np.std(py.model_value)) > 0.1  # the rate term is really at work


@pytest.mark.parametrize(
    ("family", "params"),
    [("poly", {"order": 1}), ("piecewise", {"breakpoints": [25.0]}), ("hyst", {"order": 1})],
)
def test_a_state_of_another_layout_is_refused(
    tmp_path: Path, family: str, params: dict[str, object]
) -> None:
    """Each family's generator reads only its own state layout (``thermocal-<family>-1``):
    a state of another layout (a newer format, another family's) is a ModelFileError naming
    both, not C built from fields read wrongly."""
    from thermocal.errors import ModelFileError

    T = np.linspace(10.0, 40.0, 3000)
    run = RunData(np.arange(3000.0), T[:, None], 0.1 * T, ("T1",), "r")
    m = make_model(family, **params).fit([run])
    m.signal_name = "gyro"
    save_model(m, tmp_path / "m.json")
    d = load_model_dict(tmp_path / "m.json")
    generate_c(d, prefix="ok")  # its own layout: accepted
    d["state"]["layout"] = f"thermocal-{family}-2"
    want = f"{family} state layout 'thermocal-{family}-2' is not thermocal-{family}-1"
    with pytest.raises(ModelFileError, match=want):
        generate_c(d, prefix="bad")
