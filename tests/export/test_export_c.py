"""C export (SPEC §8; issue 6): the generated C99 code, compiled with the system
compiler (cc -O2 -std=c99 -Wall -Wextra -Werror -pedantic), computes the same
model values as the Python streaming compensator, power-on included.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from thermocal.cli import main
from thermocal.compensate.kernels import StreamingCompensator
from thermocal.errors import ModelFileError
from thermocal.export.c import (
    c_harness,
    compile_harness,
    exercise_inputs,
    family_generator,
    generate_c,
    run_harness,
)
from thermocal.models.base import TemperatureModel
from thermocal.models.registry import MODEL_REGISTRY, make_model
from thermocal.models.rundata import RunData
from thermocal.pipeline.model_file import load_model, load_model_dict, save_model
from thermocal.simulate import SCENARIOS

N_SAMPLES = 100_000
N_STREAM = 15_000
REL_TOL = 1e-9


def _fit_warmup() -> TemperatureModel:
    runs = [RunData.from_recording(r, "gyro", ["T1"]) for r, _ in SCENARIOS["mems-warmup"](1)]
    return make_model("warmup").fit(runs)


def _fit_bank() -> TemperatureModel:
    res = SCENARIOS["accel-full-range"](1)
    runs = [
        RunData.from_recording(r, r.signals[0], ["T1"], known_input=tr["input"]) for r, tr in res
    ]
    m = make_model("bank").fit(runs)
    m.signal_name, m.signal_unit = "accel", "mg"
    return m


def _rlg_run() -> RunData:
    rec, _ = SCENARIOS["rlg-modelling"](1)[0]
    return RunData.from_recording(rec, "gyro", ["T1", "T2", "T3", "T4"])


def _fit_poly(**params: Any) -> Callable[[], TemperatureModel]:
    def fit() -> TemperatureModel:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # conditioning of the 37-term seed model
            m = make_model("poly", **params).fit([_rlg_run()])
        m.signal_name = "gyro"
        return m

    return fit


def _fit_piecewise(**params: Any) -> Callable[[], TemperatureModel]:
    def fit() -> TemperatureModel:
        rec, _ = SCENARIOS["fog-slow"](1)[0]
        run = RunData.from_recording(rec, "gyro", ["T1"])
        m = make_model("piecewise", **params).fit([run])
        m.signal_name = "gyro"
        return m

    return fit


def _fit_hyst() -> TemperatureModel:
    rec, _ = SCENARIOS["thermal-lag"](1, quant_c=0.0625)[0]
    m = make_model("hyst", order=2).fit([RunData.from_recording(rec, "gyro", ["T1"])])
    m.signal_name = "gyro"
    return m


FITTERS: dict[str, Callable[[], TemperatureModel]] = {
    "warmup": _fit_warmup,
    "bank": _fit_bank,
    "poly": _fit_poly(),  # seed000: 37 terms with rate and coupling terms
    # no rate or coupling terms: the C must not define the unused rate arrays/parameters
    "poly-order2": _fit_poly(terms=None, order=2),
    "poly-t-only": _fit_poly(terms="T1,T1^2,T3"),
    "piecewise": _fit_piecewise(),  # intersect method, breakpoints chosen from the data
    "piecewise-continuous": _fit_piecewise(method="continuous", breakpoints=[25.0, 30.0]),
    "piecewise-one-line": _fit_piecewise(segments=1),
    "hyst": _fit_hyst,  # the lag's state across the gap and the clamping sweep
}
"""Export cases: name → fitter (the family is the model's)."""


@pytest.fixture(scope="module", params=sorted(FITTERS))
def saved_model(
    request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory
) -> tuple[str, Path]:
    """``(family, path)`` of a saved model; the file is ``<family>.json`` in its own folder."""
    case = str(request.param)
    model = FITTERS[case]()
    fam = model.family
    d = tmp_path_factory.mktemp(f"model_{case}")
    path = d / f"{fam}.json"
    save_model(model, path)
    return fam, path


def test_every_registered_family_has_a_generator() -> None:
    import thermocal.models  # noqa: F401

    for fam, cls in MODEL_REGISTRY.items():  # declared on the class, and it resolves
        assert f"thermocal.export.c.{fam}" == cls.C_GENERATOR, fam
        assert callable(family_generator(fam))
    with pytest.raises(ModelFileError, match="no C generator for model family 'nope'"):
        family_generator("nope")


def test_c_double_equals_python_streaming(saved_model: tuple[str, Path], tmp_path: Path) -> None:
    """10⁵ samples from power-on, sweeping ±10 % beyond the fitted range (clamping), with
    a gap: the C double build equals the Python streaming compensator to 1e-9 relative.

    The Python stream runs at a few thousand samples/s for some families, so it is
    compared on the first N_STREAM samples (power-on, start-up window, gap and two
    sweeps); the whole 10⁵ are compared with the batch ``predict``, which equals the
    stream by the model contract (models/base.py).
    """
    fam, path = saved_model
    d = load_model_dict(path)
    model = load_model(path)
    tau = 1.0
    t, T, f = exercise_inputs(d, N_SAMPLES, tau, seed=7, gap_at=0.05)
    ex = generate_c(d, prefix=f"tc_{fam}", real="double", sample_interval_s=tau)
    exe = compile_harness(ex, tmp_path)
    y_c = run_harness(exe, t, T, f, tau, known_input=0.25)
    assert y_c.shape == (N_SAMPLES,)
    run = RunData(
        time_s=t, temps_c=T, signal=f, temp_names=tuple(d["temperatures"]), known_input=0.25
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # clamping warnings of the deliberate sweep
        sc = StreamingCompensator(model, tau, known_input=0.25)
        py = sc.process(t[:N_STREAM], T[:N_STREAM], f[:N_STREAM])
        batch = model.predict(run)
    scale = max(float(np.max(np.abs(batch))), 1e-300)
    err_s = np.abs(y_c[:N_STREAM] - py.model_value)
    assert float(err_s.max()) <= REL_TOL * scale, f"{fam}: max |C − stream| = {err_s.max():.3g}"
    err_b = np.abs(y_c - batch)
    assert float(err_b.max()) <= REL_TOL * scale, f"{fam}: max |C − predict| = {err_b.max():.3g}"
    assert float(np.std(batch)) > 0.0


def test_float_build_is_close(saved_model: tuple[str, Path], tmp_path: Path) -> None:
    fam, path = saved_model
    d = load_model_dict(path)
    t, T, f = exercise_inputs(d, 20_000, 1.0, seed=3)
    outs = []
    for real in ("double", "float"):
        ex = generate_c(d, prefix=f"tc_{fam}", real=real)
        assert f"typedef {real} tc_{fam}_real;" in ex.header
        outs.append(run_harness(compile_harness(ex, tmp_path / real), t, T, f, 1.0))
    scale = float(np.max(np.abs(outs[0])))
    # single precision: ~1e-7 relative per operation; a few hundred operations at most
    assert float(np.max(np.abs(outs[1] - outs[0]))) <= 1e-3 * scale


def test_generated_code_structure(saved_model: tuple[str, Path]) -> None:
    fam, path = saved_model
    d = load_model_dict(path)
    ex = generate_c(d, prefix="m")
    # identity comment block
    assert f"family:            {fam}" in ex.header
    assert d["checksum"] in ex.header
    assert f"version {d['format_version']}" in ex.header
    # no dynamic allocation, coefficients static const, clamp range present
    for text in (ex.header, ex.source):
        assert not re.search(r"\b(malloc|calloc|realloc|free)\s*\(", text)
    assert "static const m_real M_T_LO" in ex.source
    assert "void m_init(m_state *s, double sample_interval_s);" in ex.header
    assert "m_real m_update(m_state *s, double time_s" in ex.header


def _synthetic_poly(tmp_path: Path, **params: Any) -> tuple[dict[str, Any], RunData]:
    """A poly model (``params``) fitted on two slow synthetic temperatures:
    y = 0.3 + 0.02 (T1 − 20) − 0.001 (T1 − 20)² + 0.01 T2 + noise [°/h]."""
    rng = np.random.default_rng(5)
    t = np.arange(20_000, dtype=np.float64)
    T1 = 20.0 + 15.0 * np.sin(2 * np.pi * t / 7_000.0)
    T2 = 25.0 + 10.0 * np.sin(2 * np.pi * t / 11_000.0 + 0.4)
    y = 0.3 + 0.02 * (T1 - 20) - 0.001 * (T1 - 20) ** 2 + 0.01 * T2
    run = RunData(
        time_s=t,
        temps_c=np.column_stack([T1, T2]),
        signal=y + 1e-3 * rng.standard_normal(t.size),
        temp_names=("T1", "T2"),
    )
    m = make_model("poly", **params).fit([run])
    m.signal_name = "gyro"
    save_model(m, tmp_path / "m.json")
    return load_model_dict(tmp_path / "m.json"), run


NO_RATE_ARRAYS = ("_R_CENTER", "_R_SCALE", "_W_CENTER", "_W_SCALE", "RATE_BUF", "_R_LO")


@pytest.mark.parametrize(
    ("params", "n_terms", "absent", "present"),
    [
        ({"terms": None, "order": 2}, 4, NO_RATE_ARRAYS, ("_T_CENTER", "(void)time_s;")),
        ({"terms": "T1,T1^2"}, 2, NO_RATE_ARRAYS, ("_T_CENTER", "(void)s;")),
        # rate terms only: no T centre/scale, no T clamp (rates come from raw temperatures)
        ({"terms": "dT1,dT2^2"}, 2, ("_T_CENTER", "_W_CENTER", "_T_LO"), ("_R_CENTER",)),
    ],
    ids=["order2", "t1-only", "rate-only"],
)
def test_poly_term_subsets_compile_strict(
    tmp_path: Path,
    params: dict[str, Any],
    n_terms: int,
    absent: tuple[str, ...],
    present: tuple[str, ...],
) -> None:
    """Issue: a poly model without rate/coupling terms generated unused static arrays and
    parameters, rejected by -Wall -Wextra -Werror.  Only what the terms use is generated;
    the strict build compiles (compile_harness uses CFLAGS) and equals predict to 1e-9."""
    d, run = _synthetic_poly(tmp_path, **params)
    assert d["state"]["uses_rate"] is ("dT1" in str(params.get("terms")))
    assert len(d["state"]["terms"]) == n_terms
    ex = generate_c(d, prefix="sub")
    for name in absent:
        assert name not in ex.source and name not in ex.header, name
    for name in present:
        assert name in ex.source, name
    exe = compile_harness(ex, tmp_path / "c")  # cc -O2 -std=c99 -Wall -Wextra -Werror -pedantic
    y_c = run_harness(exe, run.time_s, run.temps_c, run.signal, 1.0)
    batch = load_model(tmp_path / "m.json").predict(run)
    scale = float(np.max(np.abs(batch)))
    assert float(np.max(np.abs(y_c - batch))) <= REL_TOL * scale
    if n_terms == 4:
        # the full order-2 model recovers the synthetic truth (noise σ = 1e-3 °/h,
        # 2·10⁴ samples: the fitted curve's error is ~σ·sqrt(p/n) ≈ 2e-5)
        T1, T2 = run.temps_c[:, 0], run.temps_c[:, 1]
        ref = 0.3 + 0.02 * (T1 - 20) - 0.001 * (T1 - 20) ** 2 + 0.01 * T2
        np.testing.assert_allclose(y_c, ref, rtol=0.0, atol=2e-4)


def test_poly_constant_only_compiles_strict(tmp_path: Path) -> None:
    """A poly model left with no term (e.g. by selection) exports as its constant."""
    d, run = _synthetic_poly(tmp_path, terms="T1")
    d["state"]["terms"], d["state"]["coef"] = [], []
    for real in ("double", "float"):
        ex = generate_c(d, prefix="const0", real=real)
        assert "CONST0_T_LO" not in ex.source and "CONST0_COEF" not in ex.source
        y_c = run_harness(
            compile_harness(ex, tmp_path / real), run.time_s[:50], run.temps_c[:50],
            run.signal[:50], 1.0,
        )  # fmt: skip
        c = float(d["state"]["constant"])
        np.testing.assert_allclose(y_c, c, rtol=1e-7 if real == "float" else 0.0)


def test_piecewise_export_matches_lines_and_breakpoints(tmp_path: Path) -> None:
    """The piecewise C holds the file's lines and breakpoints and evaluates eq. (1) of
    models/piecewise.py: y = A[j] + S[j]·clamp(T), j = #breakpoints ≤ T, checked against
    an independent evaluation at and around every breakpoint and beyond the range."""
    model = FITTERS["piecewise"]()
    save_model(model, tmp_path / "pw.json")
    d = load_model_dict(tmp_path / "pw.json")
    st = d["state"]
    bps = np.asarray(st["breakpoints"])
    a = np.asarray(st["intercepts"])
    s = np.asarray(st["slopes"])
    lo, hi = d["range"]["temperature_c"][d["temperatures"][0]]
    assert bps.size == 2
    T = np.concatenate(
        [[lo - 5.0, lo, hi, hi + 5.0], bps, np.nextafter(bps, -np.inf), np.linspace(lo, hi, 101)]
    )
    t = np.arange(T.size, dtype=np.float64)
    exe = compile_harness(generate_c(d, prefix="pw"), tmp_path / "c")
    y_c = run_harness(exe, t, T[:, None], np.zeros_like(t), 1.0)
    Tc = np.clip(T, lo, hi)
    j = np.array([int(np.sum(bps <= x)) for x in Tc])
    ref = a[j] + s[j] * Tc
    np.testing.assert_allclose(y_c, ref, rtol=0.0, atol=1e-12 * float(np.max(np.abs(ref))))


def test_refuses_unknown_family() -> None:
    with pytest.raises(ModelFileError, match="no C generator for model family 'nope'"):
        generate_c({"family": "nope", "temperatures": []})


def test_harness_source_is_self_contained(saved_model: tuple[str, Path]) -> None:
    _fam, path = saved_model
    ex = generate_c(load_model_dict(path), prefix="h")
    assert '#include "h.h"' in c_harness(ex)


# --- command line -------------------------------------------------------------------------------


def _run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = main(args)
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_export_c_double_and_float(
    saved_model: tuple[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    fam, path = saved_model
    code, out, err = _run(["export-c", str(path), "-o", str(tmp_path / "c"), "--json"], capsys)
    assert code == 0, err
    obj: dict[str, Any] = json.loads(out)
    assert obj["family"] == fam
    assert obj["real"] == "double"
    assert sorted(Path(p).name for p in obj["files"]) == [f"{fam}.c", f"{fam}.h"]
    # the written files compile on their own
    cc = shutil.which("cc")
    assert cc is not None
    src = tmp_path / "c" / f"{fam}.c"
    proc = subprocess.run(
        [cc, "-O2", "-std=c99", "-Wall", "-Werror", "-pedantic", "-c", str(src), "-o",
         str(tmp_path / "x.o")],
        capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    code, out, err = _run(
        ["export-c", str(path), "-o", str(tmp_path / "f"), "--float", "--json"], capsys
    )
    assert code == 0, err
    obj = json.loads(out)
    assert obj["real"] == "float"
    assert 0.0 <= obj["float_max_rel_error"] < 1e-3


def test_cli_export_refuses_corrupted_model(
    saved_model: tuple[str, Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _fam, path = saved_model
    bad = tmp_path / "bad.json"
    text = path.read_text()
    bad.write_text(text[: len(text) // 2])
    code, out, err = _run(["export-c", str(bad), "-o", str(tmp_path / "c")], capsys)
    assert code == 2
    assert out == ""
    assert err.startswith("error: ") and err.count("\n") == 1 and "corrupted" in err
    d = json.loads(text)
    d["coefficients"][0]["value"] = 1.0 + float(d["coefficients"][0]["value"])
    bad.write_text(json.dumps(d))
    code, out, err = _run(["export-c", str(bad), "-o", str(tmp_path / "c")], capsys)
    assert code == 2
    assert "checksum mismatch" in err and err.count("\n") == 1
    assert not (tmp_path / "c").exists()
