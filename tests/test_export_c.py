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
from thermocal.compensate import StreamingCompensator
from thermocal.errors import ModelFileError
from thermocal.export_c import (
    GENERATORS,
    c_harness,
    compile_harness,
    exercise_inputs,
    generate_c,
    run_harness,
)
from thermocal.models.base import (
    MODEL_REGISTRY,
    RunData,
    TemperatureModel,
    load_model,
    load_model_dict,
    make_model,
    save_model,
)
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


FITTERS: dict[str, Callable[[], TemperatureModel]] = {
    "warmup": _fit_warmup,
    "bank": _fit_bank,
}
"""How each family is fitted for the export test (added as the families appear)."""


def _register_late_families() -> None:
    import thermocal.models  # noqa: F401

    if "poly" in MODEL_REGISTRY and "poly" not in FITTERS:
        FITTERS["poly"] = _fit_poly
    if "piecewise" in MODEL_REGISTRY and "piecewise" not in FITTERS:
        FITTERS["piecewise"] = _fit_piecewise


def _fit_poly() -> TemperatureModel:
    rec, _ = SCENARIOS["rlg-modelling"](1)[0]
    run = RunData.from_recording(rec, "gyro", ["T1", "T2", "T3", "T4"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = make_model("poly").fit([run])
    m.signal_name = "gyro"
    return m


def _fit_piecewise() -> TemperatureModel:
    rec, _ = SCENARIOS["fog-slow"](1)[0]
    run = RunData.from_recording(rec, "gyro", ["T1"])
    m = make_model("piecewise").fit([run])
    m.signal_name = "gyro"
    return m


_register_late_families()


@pytest.fixture(scope="module", params=sorted(FITTERS))
def saved_model(
    request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory
) -> tuple[str, Path]:
    fam = str(request.param)
    d = tmp_path_factory.mktemp(f"model_{fam}")
    path = d / f"{fam}.json"
    save_model(FITTERS[fam](), path)
    return fam, path


def test_every_registered_family_has_a_generator() -> None:
    import thermocal.models  # noqa: F401

    missing = sorted(set(MODEL_REGISTRY) - set(GENERATORS))
    assert not missing, f"no C generator for {missing}"


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
