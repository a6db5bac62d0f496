"""Hostile ``allan`` / ``noise`` inputs of issue 39 ("Also" items and the first audit's weak
silent cases), through the CLI, every input hashed before and after.

* a constant record (a stuck sensor): exit 2 naming the column, never ADEV 0 with a
  zero-width interval and a noise type; a flat-lined one with two levels: a warning;
* ``--taus`` wholly outside the record: exit 2 naming ``--taus`` and the record's τ range
  (τ0 … m_max τ0, m_max from NIST SP 1065's term counts, written here); partly outside: a
  warning naming the τ left out, the others right;
* ``--bias-correct``/``--noise-type`` where they change nothing: a warning naming the option;
* ``--rate`` 1e-300, 1e300, negative, NaN: exit 2 naming ``--rate`` in every command tried.

The numbers asserted come from numpy in the test: the overlapping ADEV at m = 1 is
``sqrt(mean(diff(y)²)/2)`` (SP 1065 eq. 11 at m = 1), and MDEV at m = 1 equals it (SP 1065
§5.2.5: Mod σ_y(τ0) = σ_y(τ0)).
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import pytest

from thermocal.cli import main

N, TAU0 = 2000, 0.1


def _digest(p: Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest()


def _csv(path: Path, cols: dict[str, np.ndarray]) -> Path:
    lines = [",".join(cols)] + [
        ",".join(repr(float(v)) for v in row) for row in zip(*cols.values(), strict=True)
    ]
    path.write_text("\n".join(lines) + "\n")
    return path


def _white(tmp_path: Path, name: str = "white.csv") -> tuple[Path, np.ndarray]:
    y = np.random.default_rng(39).normal(0.0, 1.0, N)
    return _csv(tmp_path / name, {"time_s": np.arange(N) * TAU0, "gz_dph": y}), y


def _run(
    argv: list[str], capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> tuple[int, str, str]:
    before = {p: _digest(p) for p in tmp_path.iterdir() if p.is_file()}
    code = main(argv)
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    assert {p: _digest(p) for p in before} == before, "an input changed"
    return code, out, err


def _refused(code: int, err: str, *words: str) -> str:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert code == 2, f"exit {code}; stderr: {err}"
    assert sum(ln.startswith("error: ") for ln in lines) == 1, err
    line = next(ln for ln in lines if ln.startswith("error: "))
    for w in words:
        assert w in line, line
    return line


def _warned(err: str, *words: str) -> str:
    hits = [ln for ln in err.splitlines() if ln.startswith("warning: ") and words[0] in ln]
    assert hits, err
    for w in words[1:]:
        assert w in hits[0], hits[0]
    return hits[0]


def _adev1(y: np.ndarray) -> float:
    """Overlapping ADEV at m = 1 (SP 1065 eq. 11): sqrt(Σ (y_{i+1} − y_i)² / (2 (N − 1)))."""
    return float(np.sqrt(np.mean(np.diff(y) ** 2) / 2.0))


# --- a constant record: a stuck sensor ------------------------------------------------------


@pytest.mark.parametrize("extra", [[], ["--deviation", "oadev,totdev"], ["--data-type", "phase"]])
def test_constant_record_refused(
    extra: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    f = _csv(tmp_path / "stuck.csv", {"time_s": np.arange(N) * TAU0, "gz_dph": np.full(N, 5.0)})
    code, out, err = _run(
        ["allan", str(f), "--signal", "gz_dph", "--json", *extra], capsys, tmp_path
    )
    _refused(code, err, "stuck.csv", "'gz_dph'", "constant", "--signal")
    assert out == ""


def test_constant_gyro_axis_refused_by_noise(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rng = np.random.default_rng(1)
    t = np.arange(4000) * 0.01
    f = _csv(
        tmp_path / "tri.csv",
        {"time_s": t, "gx_dps": rng.normal(0, 0.1, t.size), "gy_dps": rng.normal(0, 0.1, t.size),
         "gz_dps": np.full(t.size, 0.5)},
    )  # fmt: skip
    out_file = tmp_path / "noise.json"
    code, _out, err = _run(
        ["noise", str(f), "--gyro", "gx_dps,gy_dps,gz_dps", "--format", "json", "-o",
         str(out_file)], capsys, tmp_path,
    )  # fmt: skip
    _refused(code, err, "tri.csv", "'gz_dps'", "constant", "--gyro")
    assert not out_file.exists()


def test_two_level_record_warned_and_right(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    y = 5.0 + 0.01 * np.random.default_rng(2).integers(0, 2, N)
    f = _csv(tmp_path / "flat.csv", {"time_s": np.arange(N) * TAU0, "gz_dph": y})
    code, out, err = _run(["allan", str(f), "--signal", "gz_dph", "--json"], capsys, tmp_path)
    assert code == 0, err
    _warned(err, "'gz_dph' takes only 2 distinct values", "flat.csv", "stuck")
    got = json.loads(out)
    assert got["tau_s"][0] == pytest.approx(TAU0)
    assert got["adev"][0] == pytest.approx(_adev1(y), rel=1e-9)


# --- --taus outside the record -------------------------------------------------------------


@pytest.mark.parametrize(
    ("extra", "top"),
    [
        # rate samples: m ≤ (N − 1)//2 = 999 (two second differences), τ ≤ 99.9 s
        ([], "99.9 s"),
        # totdev on N + 1 = 2001 phase points: m ≤ N − 1 = 1999 (SP 1065 §5.2.11), 199.9 s
        (["--deviation", "totdev"], "199.9 s"),
        (["--deviation", "mdev"], "66.7 s"),  # m ≤ (N + 2)//3 = 667 (N + 1 phase points)
    ],
)
def test_taus_outside_the_record_refused(
    extra: list[str], top: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    f, _y = _white(tmp_path)
    code, out, err = _run(
        ["allan", str(f), "--signal", "gz_dph", "--taus", "1000,5000", "--json", *extra],
        capsys, tmp_path,
    )  # fmt: skip
    _refused(code, err, "white.csv", "--taus 1000,5000", f"τ 0.1 … {top}")
    assert out == ""


@pytest.mark.parametrize("extra", [[], ["--deviation", "oadev"]])
def test_taus_partly_outside_warned_and_right(
    extra: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    f, y = _white(tmp_path)
    code, out, err = _run(
        ["allan", str(f), "--signal", "gz_dph", "--taus", "0.1,1000", "--json", *extra],
        capsys, tmp_path,
    )  # fmt: skip
    assert code == 0, err
    _warned(err, "--taus: τ 1000 s left out", "white.csv")
    got = json.loads(out)
    dev = got["adev"] if not extra else got["oadev"]
    assert got["tau_s"] == pytest.approx([TAU0])
    assert dev[0] == pytest.approx(_adev1(y), rel=1e-9)


# --- options that change nothing -----------------------------------------------------------


def test_bias_correct_on_mdev_warned(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    f, y = _white(tmp_path)
    code, out, err = _run(
        ["allan", str(f), "--signal", "gz_dph", "--deviation", "mdev", "--bias-correct",
         "--json"], capsys, tmp_path,
    )  # fmt: skip
    assert code == 0, err
    _warned(err, "--bias-correct changes nothing", "totdev and htotdev only", "mdev")
    got = json.loads(out)
    assert got["mdev"][0] == pytest.approx(_adev1(y), rel=1e-9)  # Mod σ(τ0) = σ(τ0)


def test_bias_correct_at_white_fm_warned(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """White FM (rate samples of white noise): Stable32's totdev factor is 1 (Howe 1999
    corrects flicker and random-walk FM only); nothing is corrected, and it says so."""
    f, _y = _white(tmp_path)
    code, out, err = _run(
        ["allan", str(f), "--signal", "gz_dph", "--deviation", "totdev", "--bias-correct",
         "--json"], capsys, tmp_path,
    )  # fmt: skip
    assert code == 0, err
    _warned(err, "--bias-correct changes nothing", "factor is 1", "totdev")
    got = json.loads(out)
    assert set(got["alpha"]) == {0}
    assert got["totdev_bias_factor"] == pytest.approx([1.0] * len(got["tau_s"]))


def test_noise_type_on_mtie_warned(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    f, _y = _white(tmp_path)
    code, _out, err = _run(
        ["allan", str(f), "--signal", "gz_dph", "--deviation", "mtie", "--noise-type", "wfm",
         "--json"], capsys, tmp_path,
    )  # fmt: skip
    assert code == 0, err
    _warned(err, "--noise-type changes nothing", "mtie")


def test_noise_type_with_an_interval_not_warned(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    f, _y = _white(tmp_path)
    code, _out, err = _run(
        ["allan", str(f), "--signal", "gz_dph", "--deviation", "mtie,oadev", "--noise-type",
         "wfm", "--json"], capsys, tmp_path,
    )  # fmt: skip
    assert code == 0, err
    assert "warning:" not in err, err


# --- --rate that no sensor has ---------------------------------------------------------------


RATES = ("1e-300", "1e300", "-5", "nan")


@pytest.mark.parametrize("rate", RATES)
@pytest.mark.parametrize(
    "argv",
    [
        ["allan", "{f}", "--signal", "gz"],
        ["noise", "{f}", "--gyro", "gx,gy,gz", "--format", "json", "-o", "{o}"],
        ["inspect", "{f}"],
        ["metrics", "{f}", "--signal", "gz", "--temps", "T"],
        ["fit", "{f}", "--model", "poly", "--signal", "gz", "--temps", "T", "-o", "{o}"],
    ],
    ids=["allan", "noise", "inspect", "metrics", "fit"],
)
def test_rate_no_sensor_has_refused(
    argv: list[str], rate: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A text log without a time column, its time from --rate: an absurd rate is refused
    naming --rate (1e-300 overflowed to exit 1; 1e300 made every τ 1e-300 s)."""
    rng = np.random.default_rng(3)
    body = "\n".join(
        f"{a:.6f} {b:.6f} {c:.6f} {20 + i * 0.01:.3f}"
        for i, (a, b, c) in enumerate(rng.normal(0, 1, (300, 3)))
    )
    f = tmp_path / "log.txt"
    f.write_text(body + "\n")
    o = tmp_path / "out.json"
    args = [a.format(f=f, o=o) for a in argv]
    code, _out, err = _run([*args, "--names", "gx,gy,gz,T", "--rate", rate], capsys, tmp_path)
    _refused(code, err, "--rate")
    assert not o.exists()


@pytest.mark.parametrize("rate", ["1e-300", "1e300"])
def test_profile_ramp_rate_no_chamber_has_refused(
    rate: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    o = tmp_path / "p.csv"
    code, _out, err = _run(["profile", "fog-slow", "--rate", rate, "-o", str(o)], capsys, tmp_path)
    _refused(code, err, "--rate", "°C/min")
    assert not o.exists()


# --- time ×1000 under Ṫ terms (fit) ----------------------------------------------------------


def _thermal_run(path: Path, time_factor: float, step_s: float, hours: float) -> Path:
    """A triangle −20 … 50 °C at 1 °C/min (a chamber's ramp), gz = 0.5 + 0.01 T + 0.2 Ṫ
    [deg/s, Ṫ in °C/min]; the time column written ×``time_factor``."""
    t = np.arange(0.0, hours * 3600.0, step_s)
    period = 2 * 70 * 60.0
    ph = (t % period) / period
    temp = np.where(ph < 0.5, -20 + 140 * ph, 50 - 140 * (ph - 0.5))
    rate = np.where(ph < 0.5, 1.0, -1.0)
    gz = 0.5 + 0.01 * temp + 0.2 * rate + np.random.default_rng(4).normal(0, 0.001, t.size)
    return _csv(path, {"time": t * time_factor, "T1": temp, "gz": gz})


FIT = ["fit", "--model", "poly", "--terms", "T1,dT1", "--signal", "gz", "--signal-unit",
       "deg/s", "--temps", "T1", "--temp-unit", "degC"]  # fmt: skip


def test_time_in_ms_read_as_s_under_rate_terms(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Milliseconds read as seconds: Ṫ 1000× too small (0.001 °C/min); refused by the Ṫ
    span, and the warning names the likely cause and --time-unit."""
    f = _thermal_run(tmp_path / "ms.csv", 1000.0, 10.0, 6.0)
    out = tmp_path / "m.json"
    code, _o, err = _run(
        [FIT[0], str(f), *FIT[1:], "--time-unit", "s", "-o", str(out)], capsys, tmp_path
    )
    _refused(code, err, "Ṫ spans")
    _warned(err, "ms.csv: T1: Ṫ reaches 0.001 °C/min", "ms read as s: 1 °C/min", "--time-unit")
    assert not out.exists()


def test_time_in_s_read_as_ms_under_rate_terms(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Seconds read as milliseconds: Ṫ 1000 °C/min, which no chamber does; the fit runs
    (its Ṫ coefficient 1000× small: 2e-4 for the 0.2 written here) and says why to doubt it."""
    f = _thermal_run(tmp_path / "s.csv", 1.0, 10.0, 72.0)
    out = tmp_path / "m.json"
    code, _o, err = _run(
        [FIT[0], str(f), *FIT[1:], "--time-unit", "ms", "--allow-motion", "-o", str(out)],
        capsys, tmp_path,
    )  # fmt: skip
    assert code == 0, err
    _warned(err, "s.csv: T1: Ṫ reaches 1e+03 °C/min", "s read as ms: 1 °C/min", "--time-unit")
    assert out.exists()


def test_right_time_unit_not_doubted(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    f = _thermal_run(tmp_path / "ok.csv", 1.0, 10.0, 6.0)
    out = tmp_path / "m.json"
    code, _o, err = _run(
        [FIT[0], str(f), *FIT[1:], "--time-unit", "s", "-o", str(out)], capsys, tmp_path
    )
    assert code == 0, err
    assert "Ṫ reaches" not in err and "time unit" not in err, err


def test_bias_correct_that_corrects_not_warned(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """White FM with a random walk on top: factor 1 at short τ, Howe's 1/√(1 − a τ/T) at
    long τ (a = 1/(3 ln 2) flicker FM, 3/4 random-walk FM; T = (N − 1) τ0 with N = 4001
    phase points): something is corrected, so no warning, and every factor is Howe's."""
    rng = np.random.default_rng(39)
    n = 4000
    y = rng.normal(0, 1, n) + np.cumsum(rng.normal(0, 0.03, n))
    f = _csv(tmp_path / "rw.csv", {"time_s": np.arange(n, dtype=float), "gz_dph": y})
    code, out, err = _run(
        ["allan", str(f), "--signal", "gz_dph", "--deviation", "totdev", "--bias-correct",
         "--json"], capsys, tmp_path,
    )  # fmt: skip
    assert code == 0, err
    assert "warning:" not in err, err
    got = json.loads(out)
    a_of = {-1: 1.0 / (3.0 * np.log(2.0)), -2: 0.75}
    want = [
        1.0 / np.sqrt(1.0 - a_of.get(al, 0.0) * tau / (n * 1.0))
        for al, tau in zip(got["totdev_alpha"], got["tau_s"], strict=True)
    ]
    assert got["totdev_bias_factor"] == pytest.approx(want, rel=1e-12)
    assert 1.0 in got["totdev_bias_factor"] and max(got["totdev_bias_factor"]) > 1.2


def test_taus_at_the_record_end_kept(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """τ = 99.9 s is m = 999 = ⌊(N − 1)/2⌋ for N = 2000 samples, the last m with at least
    two second differences of the N + 1 phase points (three here; m = 1000 leaves one):
    kept, not warned, its ADEV numpy's (SP 1065 eq. 11)."""
    f, y = _white(tmp_path)
    code, out, err = _run(
        ["allan", str(f), "--signal", "gz_dph", "--taus", "99.9", "--json"], capsys, tmp_path
    )
    assert code == 0, err
    assert "warning:" not in err, err
    got = json.loads(out)
    m = 999
    x = np.concatenate(([0.0], np.cumsum(y)))  # phase in units of τ0
    d = x[2 * m :] - 2 * x[m:-m] + x[: x.size - 2 * m]
    assert d.size == 3
    assert got["adev"] == pytest.approx([np.sqrt(np.mean(d**2) / (2 * m**2))], rel=1e-9)


# --- a flat-lined gyro under fit ----------------------------------------------------------------


def _sweep(path: Path, gz: np.ndarray) -> Path:
    t = np.arange(gz.size) * 10.0
    temp = 20.0 + 30.0 * np.sin(2 * np.pi * t / (3 * 3600.0))
    return _csv(path, {"time": t, "T1": temp, "gz": gz})


FIT2 = ["--model", "poly", "--order", "2", "--signal", "gz", "--signal-unit", "deg/s",
        "--temps", "T1", "--temp-unit", "degC", "--time-unit", "s"]  # fmt: skip


def test_fit_of_a_stuck_gyro_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    f = _sweep(tmp_path / "stuck.csv", np.full(2160, 0.5))
    out = tmp_path / "m.json"
    code, _o, err = _run(["fit", str(f), *FIT2, "-o", str(out)], capsys, tmp_path)
    _refused(code, err, "stuck.csv", "'gz'", "constant (0.5 in all 2160 samples)", "--signal")
    assert not out.exists()


def test_fit_of_a_two_level_gyro_warned(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    gz = 0.5 + 0.01 * np.random.default_rng(1).integers(0, 2, 2160)
    f = _sweep(tmp_path / "flat.csv", gz)
    out = tmp_path / "m.json"
    code, _o, err = _run(["fit", str(f), *FIT2, "-o", str(out)], capsys, tmp_path)
    assert code == 0, err
    _warned(err, "flat.csv: the column 'gz' takes only 2 distinct values", "(0.5, 0.51)")
    assert out.exists()


@pytest.mark.parametrize("taus", ["0,1", "nan", "-1", "inf", ""])
def test_taus_not_a_time_refused(
    taus: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    f, _y = _white(tmp_path)
    code, out, err = _run(
        ["allan", str(f), "--signal", "gz_dph", "--taus", taus, "--json"], capsys, tmp_path
    )
    _refused(code, err, f"--taus {taus!r}", "positive, finite")
    assert out == ""
