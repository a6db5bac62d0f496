"""Code injection through names into the generated C (issue 26, item 3), through the CLI.

The audit put ``#error INJECTED`` into the header with a Parquet column named
``T1 */⏎#error INJECTED⏎/*``.  Here every name a file or option gives reaches ``export-c``
hostile: the channels (``*/`` + newline + ``#error``, the C keyword ``int``, a trigraph
``??/``, quotes and a trailing backslash, non-ASCII, 300 characters), the temperatures, the
``--name`` prefix, the triads' columns and temperature, and the triads' own names.  For each:

* ``thermocal fit`` / ``turntable`` and ``export-c`` succeed, inputs byte for byte unchanged;
* the files are printable ASCII; with comments removed (a regex written here) ``INJECTED``
  is no token and every preprocessor line is ``#ifndef/#define/#endif/#include``; ``cc -E``
  preprocesses them (no ``#error``) into text where ``INJECTED`` is no token either;
* they compile with ``cc -std=c99 -Wall -Wextra -Werror -pedantic``, and the compiled C gives
  what ``thermocal compensate`` gives on the same data (1e-9 relative);
* names that meet after mapping (``a b`` / ``a-b``, a channel ``cal`` whose guard would be the
  calibration's own) are refused, exit 2, naming both, nothing written.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import re
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from thermocal.cli import main
from thermocal.export.c.harness import find_compiler

pytestmark = pytest.mark.skipif(find_compiler() is None, reason="no C compiler on this machine")

CC_STRICT = ["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic"]
INJECTED = re.compile(r"(?<![A-Za-z0-9_])INJECTED(?![A-Za-z0-9_])")
"""``INJECTED`` as a token of its own (inside a mapped identifier it is ``_INJECTED_``)."""
DIRECTIVE = re.compile(r"#(ifndef|define|endif|include)\b")

CHANNELS = [
    "g */\n#error INJECTED\n/*",
    "int",
    "gy ??/",
    "gz \"q'\\",
    "\u03c9 gyro \u00b0",
    "y" * 300,
]
TEMPS = ["T1 */\n#error INJECTED\n/*", "T2 \\"]
PREFIX = "imu */\n#error INJECTED\n"
"""The ``--name`` option, hostile too."""


def _digests(paths: list[Path]) -> dict[Path, str]:
    return {p: hashlib.sha256(p.read_bytes()).hexdigest() for p in paths}


def _run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def _cc(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [str(find_compiler()), *args], cwd=cwd, capture_output=True, text=True, check=False
    )


def _assert_inert(folder: Path, prefix: str) -> None:
    """The generated files cannot have been steered by a name (module docstring)."""
    files = [folder / f"{prefix}.h", folder / f"{prefix}.c"]
    assert sorted(p.name for p in folder.iterdir()) == sorted(p.name for p in files)
    for f in files:
        raw = f.read_bytes()
        assert all(b == 0x0A or 0x20 <= b < 0x7F for b in raw), f"{f.name}: not printable ASCII"
        text = raw.decode("ascii")
        assert not re.search(r"\?\?[=/'()!<>-]", text), "a trigraph"
        assert not re.search(r"\\[ \t]*\n", text), "a line splice"
        code = re.sub(r"/\*.*?\*/", lambda m: "\n" * m.group().count("\n"), text, flags=re.S)
        assert "/*" not in code and "*/" not in code, f"{f.name}: a comment left open or closed"
        assert not INJECTED.search(code), f"{f.name}: INJECTED outside a comment"
        for ln in code.splitlines():
            if ln.strip().startswith("#"):
                assert DIRECTIVE.match(ln.strip()), f"{f.name}: directive {ln!r}"
        proc = _cc("-std=c99", "-E", "-P", f.name, cwd=folder)
        assert proc.returncode == 0, proc.stderr
        assert not INJECTED.search(proc.stdout)
        assert not any(ln.startswith("#") for ln in proc.stdout.splitlines())
        longest = max(len(w) for w in re.findall(r"[A-Za-z_][A-Za-z0-9_]*", code))
        assert longest < 120, "an identifier of unbounded length"
    proc = _cc(*CC_STRICT, "-c", f"{prefix}.c", "-o", "obj.o", cwd=folder)
    assert proc.returncode == 0, proc.stderr
    (folder / "obj.o").unlink()


def _recording(path: Path) -> dict[str, np.ndarray]:
    """1200 s at 1 Hz: two temperatures swinging 10…40 °C (so Ṫ varies), six channels."""
    n = 1200
    t = np.arange(n, dtype=np.float64)
    t1 = 25.0 + 15.0 * np.sin(2 * np.pi * t / n * 1.3)
    t2 = t1 + 2.0 + np.sin(t / 37.0)
    rng = np.random.default_rng(26)
    cols = {"time": t}
    for i, name in enumerate(CHANNELS):
        cols[name] = 0.5 * i + 0.02 * (t1 - 25) + 1e-3 * (t2 - 20) ** 2 + rng.normal(0, 0.01, n)
    cols[TEMPS[0]], cols[TEMPS[1]] = t1, t2
    pq.write_table(pa.table(cols), path)
    return cols


CAL_DRIVER = r"""
#include <stdio.h>
#include "@p@.h"
int main(void)
{
    @p@_state s;
    double t, v;
    @p@_real temps[@P@_N_TEMPS], raw[@P@_N_CHANNELS], out[@P@_N_CHANNELS];
    int i;
    @p@_init(&s, 1.0);
    while (scanf("%lf", &t) == 1) {
        for (i = 0; i < @P@_N_TEMPS; ++i) {
            if (scanf("%lf", &v) != 1) return 2;
            temps[i] = v;
        }
        for (i = 0; i < @P@_N_CHANNELS; ++i) {
            if (scanf("%lf", &v) != 1) return 2;
            raw[i] = v;
        }
        @p@_compensate(&s, t, temps, raw, out);
        for (i = 0; i < @P@_N_CHANNELS; ++i) printf("%.17g ", (double)out[i]);
        printf("\n");
    }
    return 0;
}
"""


def _run_c(folder: Path, prefix: str, driver: str, rows: np.ndarray) -> np.ndarray:
    (folder / "main.c").write_text(driver.replace("@p@", prefix).replace("@P@", prefix.upper()))
    proc = _cc(*CC_STRICT, "-o", "run", f"{prefix}.c", "main.c", cwd=folder)
    assert proc.returncode == 0, proc.stderr
    text = "\n".join(" ".join(repr(float(v)) for v in row) for row in rows.tolist())
    res = subprocess.run(
        [str(folder / "run")], input=text, capture_output=True, text=True, check=True
    )
    return np.array([[float(v) for v in ln.split()] for ln in res.stdout.splitlines()])


@pytest.mark.parametrize(
    "fit_options",
    [
        ["--model", "poly", "--terms", "T1,T1^2,dT1,T1*dT1,T2", "--rate-interval", "30"],
        ["--model", "piecewise", "--breakpoints", "25"],
    ],
    ids=["poly-rate-two-temps", "piecewise"],
)
def test_hostile_channel_and_temperature_names_give_inert_c_equal_to_python(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], fit_options: list[str]
) -> None:
    data = tmp_path / "run.parquet"
    cols = _recording(data)
    temps = TEMPS if "poly" in fit_options else TEMPS[:1]
    cal = tmp_path / "cal.json"
    before = _digests([data])
    code, _, err = _run(
        capsys, "fit", str(data), *fit_options, "--signal", ",".join(CHANNELS),
        "--temps", ",".join(temps), "--signal-unit", "deg/h", "--temp-unit", "degC",
        "--time-unit", "s", "-o", str(cal),
    )  # fmt: skip
    assert code == 0, err
    before |= _digests([cal])
    cdir = tmp_path / "c"
    code, out, err = _run(capsys, "export-c", str(cal), "-o", str(cdir), "--name", PREFIX, "--json")
    assert code == 0, err
    prefix = json.loads(out)["prefix"]
    _assert_inert(cdir, prefix)
    assert prefix == "imu_error_injected"  # "imu */⏎#error INJECTED⏎" as an identifier
    header = (cdir / f"{prefix}.h").read_text()
    # the channel "int": its functions under imu_error_injected_c_int_, a member c_int
    assert "imu_error_injected_c_int_state c_int;" in header
    # the compiled C equals thermocal compensate on the same samples
    comp = tmp_path / "comp.parquet"
    code, _, err = _run(capsys, "compensate", str(cal), str(data), "-o", str(comp))
    assert code == 0, err
    assert _digests([data, cal]) == before
    py = pd.read_parquet(comp)
    rows = np.column_stack([cols["time"], *(cols[t] for t in temps), *(cols[c] for c in CHANNELS)])
    c_out = _run_c(cdir, prefix, CAL_DRIVER, rows)
    assert c_out.shape == (rows.shape[0], len(CHANNELS))
    for i, name in enumerate(CHANNELS):
        ref = py[f"{name}_comp"].to_numpy()
        scale = max(1.0, float(np.max(np.abs(ref))))
        np.testing.assert_allclose(c_out[:, i], ref, rtol=0, atol=1e-9 * scale, err_msg=name)


@pytest.mark.parametrize(
    ("names", "prefix", "words"),
    [
        (["a b", "a-b"], "imu", ["'a b'", "'a-b'", "a_b"]),  # the same identifier
        (["GX", "gx"], "imu", ["'GX'", "'gx'"]),  # C names are lower case
        (["int", "c_int"], "imu", ["'int'", "'c_int'"]),  # the keyword's escape
        (["cal", "x"], "imu", ["'cal'", "IMU_CAL_H"]),  # its guard is the calibration's
    ],
)
def test_channel_names_that_meet_in_c_are_refused(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    names: list[str],
    prefix: str,
    words: list[str],
) -> None:
    n = 400
    t = np.arange(n, dtype=np.float64)
    temp = 10.0 + 30.0 * t / (n - 1)
    data = tmp_path / "run.parquet"
    pq.write_table(
        pa.table({"time": t, names[0]: 0.01 * temp, names[1]: 0.02 * temp, "T": temp}), data
    )
    cal = tmp_path / "cal.json"
    code, _, err = _run(
        capsys, "fit", str(data), "--model", "poly", "--order", "1", "--signal", ",".join(names),
        "--temps", "T", "--signal-unit", "deg/h", "--temp-unit", "degC", "--time-unit", "s",
        "-o", str(cal),
    )  # fmt: skip
    assert code == 0, err
    before = _digests([data, cal])
    cdir = tmp_path / "c"
    code, out, err = _run(capsys, "export-c", str(cal), "-o", str(cdir), "--name", prefix)
    assert code == 2, out
    last = err.strip().splitlines()[-1]
    assert last.startswith("error: ")
    for w in words:
        assert w in last, last
    assert not cdir.exists() or not any(cdir.iterdir())
    assert _digests([data, cal]) == before


# --- triads -----------------------------------------------------------------------------------

TRIAD_COLUMNS = {
    "gyro_x": "gx */\n#error INJECTED\n/*",
    "gyro_y": "gy ??/",
    "gyro_z": "gz \"q'\\",
    "accel_x": "int",
    "accel_y": "ax \u03c9 \u00b0",
    "accel_z": "z" * 300,
    "T_imu": "T */\n#error INJECTED\n#",
}
G_COLS = [TRIAD_COLUMNS[f"gyro_{a}"] for a in "xyz"]
A_COLS = [TRIAD_COLUMNS[f"accel_{a}"] for a in "xyz"]

TRIAD_DRIVER = r"""
#include <stdio.h>
#include "@p@.h"
int main(void)
{
    double t, x[6], g[3], a[3];
    while (scanf("%lf %lf %lf %lf %lf %lf %lf", &t, &x[0], &x[1], &x[2], &x[3], &x[4], &x[5])
           == 7) {
        @GYRO@_correct(t, x, g);
        @ACCEL@_correct(t, x + 3, a);
        printf("%.17g %.17g %.17g %.17g %.17g %.17g\n", g[0], g[1], g[2], a[0], a[1], a[2]);
    }
    return 0;
}
"""


@pytest.fixture(scope="module")
def triad_runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, object]:
    """Simulated turntable runs at six soaks and a held-out run, written as Parquet with the
    hostile column names, and the calibration ``thermocal turntable`` makes of them."""
    from thermocal.turntable.simulate import simulate_turntable_thermal

    d = tmp_path_factory.mktemp("triads")
    soaks, held = [], None
    for rec, truth in simulate_turntable_thermal(seed=3):
        cols = {"time": rec.time_s, "alpha_deg": rec.column("alpha_deg"),
                "beta_deg": rec.column("beta_deg")}  # fmt: skip
        cols |= {new: rec.column(old) for old, new in TRIAD_COLUMNS.items()}
        f = d / f"{truth['label']}.parquet"
        pq.write_table(pa.table(cols), f)
        if truth["held_out"]:
            held = f
        else:
            soaks.append(f)
    assert held is not None
    before = _digests([*soaks, held])
    cal = d / "cal.json"
    code = main(["turntable", *map(str, soaks), "--temps", TRIAD_COLUMNS["T_imu"],
                 "--gyro", ",".join(G_COLS), "--accel", ",".join(A_COLS), "--gyro-unit", "deg/s",
                 "--accel-unit", "m/s^2", "--time-unit", "s", "--latitude", "40",
                 "-o", str(cal)])  # fmt: skip
    assert code == 0
    comp = d / "comp.parquet"
    assert main(["compensate", str(cal), str(held), "-o", str(comp)]) == 0
    assert _digests([*soaks, held]) == before
    return {"cal": cal, "held": held, "comp": comp, "dir": d}


def _triad_check(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    cal: Path,
    runs: dict[str, object],
    functions: tuple[str, str],
) -> None:
    before = _digests([cal, runs["held"]])  # type: ignore[list-item]
    cdir = tmp_path / "c"
    code, out, err = _run(capsys, "export-c", str(cal), "-o", str(cdir), "--name", PREFIX, "--json")
    assert code == 0, err
    prefix = json.loads(out)["prefix"]
    _assert_inert(cdir, prefix)
    assert prefix == "imu_error_injected"
    held = pd.read_parquet(runs["held"])  # type: ignore[arg-type]
    rows = held[[TRIAD_COLUMNS["T_imu"], *G_COLS, *A_COLS]].to_numpy()
    driver = TRIAD_DRIVER.replace("@GYRO@", functions[0]).replace("@ACCEL@", functions[1])
    c_out = _run_c(cdir, prefix, driver, rows)
    py = pd.read_parquet(runs["comp"])  # type: ignore[arg-type]
    ref = py[[f"{c}_comp" for c in [*G_COLS, *A_COLS]]].to_numpy()
    np.testing.assert_allclose(c_out, ref, rtol=1e-9, atol=1e-9)
    assert _digests([cal, runs["held"]]) == before  # type: ignore[list-item]


def test_hostile_triad_columns_and_temperature_give_inert_c_equal_to_python(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], triad_runs: dict[str, object]
) -> None:
    _triad_check(
        tmp_path,
        capsys,
        triad_runs["cal"],  # type: ignore[arg-type]
        triad_runs,
        ("imu_error_injected_gyro", "imu_error_injected_accel"),
    )


def test_hostile_triad_names_give_inert_c_equal_to_python(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], triad_runs: dict[str, object]
) -> None:
    """The triads renamed in the calibration file (a file anyone can write): the keyword
    ``int`` and a 300-character name ending in ``*/⏎#error INJECTED``."""
    from thermocal.pipeline.model_file import load_calibration, save_calibration

    cal = load_calibration(triad_runs["cal"])  # type: ignore[arg-type]
    long = "w" * 300 + " */\n#error INJECTED\n"
    assert [t.name for t in cal.triads] == ["gyro", "accel"]
    cal.triads = [
        dataclasses.replace(cal.triads[0], name="int"),
        dataclasses.replace(cal.triads[1], name=long),
    ]
    path = tmp_path / "renamed.json"
    save_calibration(cal, path)
    # 300 characters: 54 of them, '_' and the first 8 hex digits of the name's SHA-256
    long_id = "w" * 54 + "_" + hashlib.sha256(long.encode()).hexdigest()[:8]
    _triad_check(
        tmp_path,
        capsys,
        path,
        triad_runs,
        ("imu_error_injected_c_int", f"imu_error_injected_{long_id}"),
    )


def test_triad_names_that_meet_in_c_are_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], triad_runs: dict[str, object]
) -> None:
    from thermocal.pipeline.model_file import load_calibration, save_calibration

    cal = load_calibration(triad_runs["cal"])  # type: ignore[arg-type]
    cal.triads = [
        dataclasses.replace(cal.triads[0], name="a b"),
        dataclasses.replace(cal.triads[1], name="a-b"),
    ]
    path = tmp_path / "same.json"
    save_calibration(cal, path)
    before = _digests([path])
    cdir = tmp_path / "c"
    code, out, err = _run(capsys, "export-c", str(path), "-o", str(cdir))
    assert code == 2, out
    last = err.strip().splitlines()[-1]
    assert last.startswith("error: ") and "'a b'" in last and "'a-b'" in last, last
    assert not cdir.exists() or not any(cdir.iterdir())
    assert _digests([path]) == before
