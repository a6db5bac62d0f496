"""C export in the data's unit (issue 13, bug 7): the exported C took and returned °/h
whatever the unit the data were in.  Now the functions work in the unit the model was
fitted on as the data gave it (``--unit`` for another), name it in every function's
comment, and accept raw-count temperatures when the model is in counts.  Each C result is
compared with ``thermocal compensate`` on the same file (1e-9 relative)."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from thermocal import units
from thermocal.cli import main
from thermocal.export.c import compile_harness, generate_c, run_harness
from thermocal.models.format import checksum
from thermocal.pipeline.model_file import load_model_dict

needs_cc = pytest.mark.skipif(
    not any(shutil.which(c) for c in ("cc", "gcc", "clang")), reason="no C compiler"
)
REL_TOL = 1e-9
TERMS = "T1,T1^2,dT1"  # a rate term: the C keeps state, the time base matters


def _run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def _data(tmp_path: Path, temp: str = "degC") -> tuple[Path, pd.DataFrame]:
    """A gyro in °/s over 1500 s at 1 Hz; temperatures in °C, raw counts, or signed
    16-bit counts stored unsigned (LSB 1/128 °C about 25 °C)."""
    rng = np.random.default_rng(11)
    n = 1500
    t = np.arange(n, dtype=float)
    tc = np.round((25.0 + 15.0 * np.sin(2 * np.pi * t / n)) * 128.0) / 128.0
    gyro = 0.01 + 2e-4 * (tc - 25.0) + 1e-5 * rng.standard_normal(n)
    col = {"degC": tc, "counts": np.round(tc * 128.0)}.get(temp)
    if col is None:  # int16
        v = np.round((tc - 25.0) * 128.0)
        col = np.where(v < 0, v + 65536.0, v)
    df = pd.DataFrame({"time": t, "gyro": gyro, "T1": col})
    src = tmp_path / "run.csv"
    df.to_csv(src, index=False)
    return src, df


def _fit(capsys: pytest.CaptureFixture[str], src: Path, model: Path, *extra: str) -> None:
    code, _, err = _run(
        capsys, "fit", str(src), "--model", "poly", "--terms", TERMS, "--signal", "gyro",
        "--signal-unit", "deg/s", "--temps", "T1", "--time-unit", "s", *extra, "-o", str(model),
    )  # fmt: skip
    assert code == 0, err


def _python_model(
    capsys: pytest.CaptureFixture[str], model: Path, src: Path, tmp_path: Path
) -> np.ndarray:
    out = tmp_path / "comp.csv"
    code, _, err = _run(capsys, "compensate", str(model), str(src), "-o", str(out))
    assert code == 0, err
    return np.asarray(pd.read_csv(out)["gyro_model"], dtype=float)


@needs_cc
def test_c_works_in_the_data_unit_by_default(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    src, df = _data(tmp_path)
    model = tmp_path / "m.json"
    _fit(capsys, src, model, "--temp-unit", "degC")
    code, out, err = _run(capsys, "export-c", str(model), "-o", str(tmp_path / "c"), "--json")
    assert code == 0, err
    info = json.loads(out)
    assert (info["unit"], info["model_unit"]) == ("deg/s", "deg/h")
    header = (tmp_path / "c" / "m.h").read_text()
    assert '#define M_SIGNAL_UNIT "deg/s"' in header
    # every public function's comment names the unit
    for fn in ("m_set_known_input", "m_update", "m_compensate"):
        decl = header.index(f" {fn}(")
        comment = header[header.rindex("/*", 0, decl) : decl]
        assert "[deg/s]" in comment, fn
    ex = generate_c(load_model_dict(model), prefix="m")
    y_c = run_harness(
        compile_harness(ex, tmp_path / "build"),
        df["time"].to_numpy(), df[["T1"]].to_numpy(), df["gyro"].to_numpy(), 1.0,
    )  # fmt: skip
    y_py = _python_model(capsys, model, src, tmp_path)
    np.testing.assert_allclose(y_c, y_py, rtol=REL_TOL, atol=REL_TOL * np.abs(y_py).max())
    # another unit on request: rad/s, same physical values
    ex_r = generate_c(load_model_dict(model), prefix="mr", unit="rad/s")
    assert ex_r.unit == "rad/s" and '"rad/s"' in ex_r.header
    y_r = run_harness(
        compile_harness(ex_r, tmp_path / "build_r"), df["time"].to_numpy(),
        df[["T1"]].to_numpy(), df["gyro"].to_numpy() * units.DEG_TO_RAD, 1.0,
    )  # fmt: skip
    np.testing.assert_allclose(y_r / units.DEG_TO_RAD, y_py, rtol=REL_TOL, atol=1e-15)
    code, _, err = _run(capsys, "export-c", str(model), "-o", str(tmp_path / "x"), "--unit", "mg")
    assert code == 2 and "'deg/h'" in err and "'mg'" in err


@needs_cc
def test_model_in_counts_takes_raw_counts(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    src, df = _data(tmp_path, "counts")
    model = tmp_path / "m.json"
    _fit(capsys, src, model, "--temp-unit", "counts")
    capsys.readouterr()
    d = load_model_dict(model)
    ex = generate_c(d, prefix="mc")
    assert '#define MC_TEMPERATURE_UNIT "counts"' in ex.header
    assert "temps_c [counts]" in ex.header and "[degC]" not in ex.header
    y_c = run_harness(
        compile_harness(ex, tmp_path / "build"),
        df["time"].to_numpy(), df[["T1"]].to_numpy(), df["gyro"].to_numpy(), 1.0,
    )  # fmt: skip
    y_py = _python_model(capsys, model, src, tmp_path)
    np.testing.assert_allclose(y_c, y_py, rtol=REL_TOL, atol=REL_TOL * np.abs(y_py).max())


HARNESS = r"""#include <stdio.h>
#include "{p}.h"
int main(void)
{{
    double counts[1];
    {p}_real t[1];
    while (scanf("%lf", &counts[0]) == 1) {{
        {p}_temps_from_counts(counts, t);
        printf("%.17g\n", (double)t[0]);
    }}
    return 0;
}}
"""


@needs_cc
def test_signed_counts_conversion_in_c(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A model fitted on int16 counts with their conversion gets `<p>_temps_from_counts`,
    which makes the counts signed before the gain — the firmware feeds what it reads."""
    src, df = _data(tmp_path, "int16")
    model = tmp_path / "m.json"
    _fit(capsys, src, model, "--temp-conversion", "0.0078125,25,int16")
    ex = generate_c(load_model_dict(model), prefix="mi")
    d = tmp_path / "build"
    ex.write(d)
    (d / "main.c").write_text(HARNESS.format(p="mi"))
    cc = next(shutil.which(c) for c in ("cc", "gcc", "clang") if shutil.which(c))
    exe = d / "conv"
    subprocess.run(
        [str(cc), "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-o", str(exe),
         str(d / "mi.c"), str(d / "main.c")],
        check=True, capture_output=True,
    )  # fmt: skip
    raw = np.array([0.0, 1.0, 32767.0, 32768.0, 65535.0, 63616.0])
    proc = subprocess.run(
        [str(exe)],
        input="\n".join(repr(float(x)) for x in raw),
        capture_output=True,
        text=True,
        check=True,
    )
    got = np.array([float(x) for x in proc.stdout.split()])
    signed = np.array([0.0, 1.0, 32767.0, -32768.0, -1.0, -1920.0])  # written out
    np.testing.assert_array_equal(got, signed * 0.0078125 + 25.0)
    assert raw[-1] in set(df["T1"])  # 10 °C as the logger wrote it


def test_older_model_file_exports_in_its_own_unit_with_a_warning(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    src, _ = _data(tmp_path)
    model = tmp_path / "m.json"
    _fit(capsys, src, model, "--temp-unit", "degC")
    d = json.loads(model.read_text())
    d = {k: v for k, v in d.items() if k not in ("inputs", "checksum")}
    d["format_version"] = 2
    d["checksum"] = checksum(d)
    old = tmp_path / "old.json"
    old.write_text(json.dumps(d))
    code, out, err = _run(capsys, "export-c", str(old), "-o", str(tmp_path / "c"), "--json")
    assert code == 0, err
    assert json.loads(out)["unit"] == "deg/h"
    assert "warning: " in err and "does not record the unit its data were in" in err
