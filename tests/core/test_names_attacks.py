"""Names never steer a generated file (issue 39 item 5 and "What to build" 1/3), through
the CLI.

A column name, a file name, an option's text can hold a newline, a carriage return, the
line separators U+2028 and U+0085 (YAML line breaks), NUL, ``#``, ``"``, ``*/``,
``<script>``, backticks, ``%`` or 5000 characters.  Each generated file either refuses it
(exit 2, one ``error:`` line naming the option) or escapes it so that its consumer reads
the same keys and values as with plain names:

* Kalibr's ``imu.yaml`` (``noise``), read with PyYAML's ``safe_load`` (Kalibr's loader) and
  line by line: each key once, the numbers those of the same record under plain names and
  near the simulator's truth; ``--gyro gx,gx,gx``, ``--accel`` naming the gyro's columns
  and a hostile ``--rostopic`` refused; a time axis ×1000 (ms read as s) warned, its
  densities √1000 = 31.6× those of the true axis (σ_n = σ(τ)·√τ at the same samples);
* C (``export-c``): names holding ``???/`` (a trigraph left by escaping ``??`` once) and a
  backslash followed by blanks (a line splice for gcc: checked with gcc itself) compile
  with ``-Werror`` and declare nothing else;
* JSON and TOML inputs nested 100 000 deep (``--poses``, a sidecar, a fleet or station
  configuration): exit 2 naming the file, not a RecursionError.
"""

from __future__ import annotations

import hashlib
import math
import re
import subprocess
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
import yaml

from thermocal.cli import main
from thermocal.errors import ThermocalInputError
from thermocal.export.c.harness import find_compiler
from thermocal.identifiers import check_generated_c, one_line
from thermocal.stability.noise_model import check_kalibr_yaml

KALIBR_KEYS = {  # Kalibr's imu.yaml (the Kalibr wiki, "IMU Noise Model"), written here
    "accelerometer_noise_density",
    "accelerometer_random_walk",
    "gyroscope_noise_density",
    "gyroscope_random_walk",
    "update_rate",
    "rostopic",
}
FS_HZ = 100.0
DURATION_S = 300.0
GYRO_DENSITY = (1.5e-4, 1.6e-4, 1.7e-4)  # rad/s/√Hz: the simulator's truth
ACCEL_DENSITY = (2.0e-3, 2.1e-3, 2.2e-3)  # m/s²/√Hz
PLAIN = ("gx", "gy", "gz", "ax", "ay", "az")
INJECTION = "gz\ngyroscope_noise_density: 1.0e-12\n#"
"""The issue's name: a newline, a second key, a comment to swallow the rest of the line."""
HOSTILE_A = (
    "gx\rgyroscope_noise_density: 1.0e-12",
    "gy\u2028gyroscope_random_walk: 1.0e-12\u2028#",
    INJECTION,
    "ax\x85accelerometer_noise_density: 1.0e-12",
    "ay\x00 # \"q\" 'r' `rm -rf` %s %n {0}",
    "az <script>alert(1)</script> */ /* \u202e",
)
HOSTILE_B = (
    "g" * 5000,
    "gy: 1\n---\n!!python/object:os.system",
    "gz\n\nupdate_rate: 1.0\nrostopic: '/evil'",
    "ax\x1c\x1d\x1e\x0b\x0cx",
    "ay\ufeff\ue000\U000e0001",
    "az\tfoo: bar",
)


def _digest(paths: list[Path]) -> dict[str, str]:
    return {str(p): hashlib.sha256(p.read_bytes()).hexdigest() for p in paths}


def _run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def _error_line(err: str) -> str:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1, err
    assert lines[0].startswith("error: "), err
    return lines[0]


def _imu(path: Path, names: tuple[str, ...], time_scale: float = 1.0) -> Path:
    """300 s at 100 Hz of a 6-axis IMU at rest: white noise of known density (discrete
    σ = σ_n/√Δt) in rad/s and m/s² (+1 g on the last axis), the same samples whatever the
    names; the time column ``time [s]`` multiplied by ``time_scale``."""
    rng = np.random.default_rng(39)
    n = int(DURATION_S * FS_HZ)
    dt = 1.0 / FS_HZ
    cols = {"time [s]": np.arange(n) * dt * time_scale}
    for name, d, g in zip(
        names, GYRO_DENSITY + ACCEL_DENSITY, (0, 0, 0, 0, 0, 9.80665), strict=True
    ):
        cols[name] = g + rng.normal(0.0, d / math.sqrt(dt), n)
    pq.write_table(pa.table(cols), path)
    return path


def _noise(path: Path, out: Path, names: tuple[str, ...], *extra: str) -> list[str]:
    return [
        "noise", str(path), "--gyro", ",".join(names[:3]), "--accel", ",".join(names[3:]),
        "--gyro-unit", "rad/s", "--accel-unit", "m/s^2", "--time", "time [s]",
        "-o", str(out), *extra,
    ]  # fmt: skip


@pytest.fixture(scope="module")
def plain_yaml(tmp_path_factory: pytest.TempPathFactory) -> tuple[str, dict[str, object]]:
    d = tmp_path_factory.mktemp("kalibr-plain")
    data = _imu(d / "imu.parquet", PLAIN)
    out = d / "imu.yaml"
    assert main(_noise(data, out, PLAIN)) == 0
    text = out.read_text(encoding="utf-8")
    return text, yaml.safe_load(text)


def _check_kalibr(text: str, reference: dict[str, object]) -> None:
    """Kalibr reads the same keys and values as from the plain names, each key on one line
    of its own, and the densities are the simulator's."""
    doc = yaml.safe_load(text)
    assert set(doc) == KALIBR_KEYS
    assert doc == reference
    for key in KALIBR_KEYS:
        assert len(re.findall(rf"^{key}:", text, flags=re.M)) == 1, key
    assert not re.search("[\r\x85\u2028\u2029\x00]", text)
    assert doc["gyroscope_noise_density"] == pytest.approx(max(GYRO_DENSITY), rel=0.15)
    assert doc["accelerometer_noise_density"] == pytest.approx(max(ACCEL_DENSITY), rel=0.15)


def test_hostile_column_input_and_output_names_do_not_steer_kalibr_yaml(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], plain_yaml: tuple[str, dict[str, object]]
) -> None:
    """The issue's column name (and five others), an input file name and an output file
    name holding a newline and a key: the YAML Kalibr reads is that of the plain names."""
    data = _imu(tmp_path / "imu\ngyroscope_noise_density: 1.0e-12\n#.parquet", HOSTILE_A)
    out = tmp_path / "out\nrostopic: 'evil'\n#.yaml"
    before = _digest([data])
    code, _, err = _run(capsys, *_noise(data, out, HOSTILE_A))
    assert code == 0, err
    assert not any(ln.startswith("error") for ln in err.splitlines()), err
    _check_kalibr(out.read_text(encoding="utf-8"), plain_yaml[1])
    assert _digest([data]) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([data.name, out.name])


def test_more_hostile_names_do_not_steer_kalibr_yaml(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], plain_yaml: tuple[str, dict[str, object]]
) -> None:
    data = _imu(tmp_path / "imu.parquet", HOSTILE_B)
    out = tmp_path / "imu.yaml"
    code, _, err = _run(capsys, *_noise(data, out, HOSTILE_B))
    assert code == 0, err
    _check_kalibr(out.read_text(encoding="utf-8"), plain_yaml[1])


@pytest.mark.parametrize(
    ("gyro", "accel", "option", "words"),
    [
        ("gx,gx,gx", "ax,ay,az", "--gyro", "'gx' named twice"),
        ("gx,gy,gz", "gx,gy,gz", "--accel", "'gx' also in --gyro"),
        ("gx,gy,gz", "ax,gz,az", "--accel", "'gz' also in --gyro"),
        ("gx,gy,gz", "ax,ax,az", "--accel", "'ax' named twice"),
    ],
)
def test_a_column_named_twice_is_refused(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    gyro: str,
    accel: str,
    option: str,
    words: str,
) -> None:
    """Kalibr would get one sensor's noise for another's (or an accelerometer without its
    keys): refused before anything is read."""
    data = _imu(tmp_path / "imu.parquet", PLAIN)
    out = tmp_path / "imu.yaml"
    code, _, err = _run(
        capsys, "noise", str(data), "--gyro", gyro, "--accel", accel, "-o", str(out)
    )
    assert code == 2, err
    line = _error_line(err)
    assert line.startswith(f"error: {option} ") and words in line, line
    assert not out.exists()


def test_the_library_refuses_an_axis_twice() -> None:
    """:func:`noise_model` itself (a caller of the library passes no option)."""
    from thermocal.stability.noise_model import axis_noise, noise_model

    rng = np.random.default_rng(1)
    v = rng.normal(0.0, 1e-3, 4000)
    ax = axis_noise(v, 0.01, name="gx", sensor="gyro", unit="rad/s")
    with pytest.raises(
        ThermocalInputError, match=r"^gyro 'gx': column named twice \(also in gyro\)"
    ):
        noise_model([ax, ax, ax], 100.0)


@pytest.mark.parametrize(
    "topic", ['/imu0"\nx: 1', "/imu0\u2028rostopic: /b", "", "imu 0", "/imu0#", "/imu\x00"]
)
def test_a_hostile_rostopic_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], topic: str
) -> None:
    """A ROS topic is a graph resource name (ROS wiki "Names" 1.1.1); anything else is not
    the topic of any bag, whatever the YAML quoting."""
    from thermocal.stability.noise_model import axis_noise, noise_model

    rng = np.random.default_rng(1)
    axes = [
        axis_noise(rng.normal(0.0, 1e-3, 4000), 0.01, name=n, sensor="gyro", unit="rad/s")
        for n in ("gx", "gy", "gz")
    ]
    with pytest.raises(ThermocalInputError, match=r"^rostopic .*not a ROS topic name"):
        noise_model(axes, 100.0, rostopic=topic)
    for good in ("/imu0", "/camera/imu", "~imu", "imu_0"):
        noise_model(axes, 100.0, rostopic=good)


def test_a_hostile_rostopic_through_the_cli(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    data = _imu(tmp_path / "imu.parquet", PLAIN)
    out = tmp_path / "imu.yaml"
    code, _, err = _run(capsys, *_noise(data, out, PLAIN, "--rostopic", '/imu0"\nx: 1'))
    assert code == 2, err
    assert _error_line(err).startswith("error: --rostopic "), err
    assert not out.exists()


def test_time_in_ms_read_as_s_is_warned_and_scales_the_densities_by_sqrt_1000(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], plain_yaml: tuple[str, dict[str, object]]
) -> None:
    """The time column holds ms but says s: the rate reads 0.1 Hz and every white-noise
    density √1000 = 31.6× too large (σ_n = σ(τ)·√τ, the same σ at 1000× the τ).  The file is
    written (the numbers follow from what the file says) with a warning naming the rate and
    --time-unit."""
    data = _imu(tmp_path / "imu.parquet", PLAIN, time_scale=1000.0)
    out = tmp_path / "imu.yaml"
    code, _, err = _run(capsys, *_noise(data, out, PLAIN))
    assert code == 0, err
    warned = [ln for ln in err.splitlines() if "update rate 0.1 Hz" in ln]
    assert len(warned) == 1 and warned[0].startswith("warning: ") and "--time-unit" in warned[0]
    assert str(data) in warned[0]
    doc = yaml.safe_load(out.read_text(encoding="utf-8"))
    ref = plain_yaml[1]
    assert doc["update_rate"] == pytest.approx(FS_HZ / 1000.0, rel=1e-12)
    for key in ("gyroscope_noise_density", "accelerometer_noise_density"):
        assert doc[key] == pytest.approx(ref[key] * math.sqrt(1000.0), rel=1e-5), key


@pytest.mark.parametrize(
    ("rate_hz", "density", "sensor", "words"),
    [
        (9.9, 1.0e-4, "gyro", r"^f\.csv: update rate 9\.9 Hz .*give time_unit \("),
        (1.01e5, 1.0e-4, "gyro", r"^f\.csv: update rate 101000 Hz"),
        (100.0, 1.2e-2, "gyro", r"x: noise density 0\.01[12]\d* rad/s/sqrt\(Hz\) lies outside"),
        (100.0, 8.0e-10, "gyro", r"x: noise density [78]\.\d*e-10 rad/s/sqrt\(Hz\) lies out"),
        (100.0, 0.12, "accel", r"x: noise density 0\.1[12]\d* m/s\^2/sqrt\(Hz\) lies outsi"),
        (100.0, 8.0e-9, "accel", r"x: noise density [78]\.\d*e-09 m/s\^2/sqrt\(Hz\) lies ou"),
    ],
)
def test_rates_and_densities_no_imu_has_are_warned(
    rate_hz: float, density: float, sensor: str, words: str
) -> None:
    """Bounds: an estimator's IMU at 10 Hz … 100 kHz; gyro densities 1e-9 … 1e-2
    rad/s/√Hz, accelerometer 1e-8 … 1e-1 m/s²/√Hz (sources in
    :data:`thermocal.stability.noise_model.IMU_DENSITY`); just inside: no warning."""
    import warnings

    from thermocal.errors import PlausibilityWarning
    from thermocal.stability.noise_model import axis_noise, noise_model

    dt = 1.0 / rate_hz
    rng = np.random.default_rng(3)
    unit = "rad/s" if sensor == "gyro" else "m/s^2"
    ax = axis_noise(
        rng.normal(0.0, density / math.sqrt(dt), 20000), dt, name="x", sensor=sensor, unit=unit
    )
    with pytest.warns(PlausibilityWarning, match=words):
        noise_model([ax], rate_hz, where="f.csv")
    inside_rate = min(max(rate_hz, 10.0), 1.0e5)
    inside = rng.normal(0.0, 1e-4 / math.sqrt(1 / inside_rate), 20000)
    unit_ok = axis_noise(inside, 1 / inside_rate, name="x", sensor="gyro", unit="rad/s")
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlausibilityWarning)
        noise_model([unit_ok], inside_rate)


def test_the_kalibr_backstop_refuses_steered_text(
    plain_yaml: tuple[str, dict[str, object]],
) -> None:
    """The writer's last check: the plain file passes; a key twice (PyYAML keeps the last),
    a line break YAML knows and Python's split does not, a stray line, a key missing, a
    value YAML would read as text are each refused."""
    text = plain_yaml[0]
    check_kalibr_yaml(text)
    assert yaml.safe_load(text + "gyroscope_noise_density: 1.0e-12\n")[
        "gyroscope_noise_density"
    ] == pytest.approx(1e-12)  # why a second key is dangerous
    for bad, words in [
        (text + "gyroscope_noise_density: 1.0e-12\n", "written twice"),
        (text.replace("# IMU", "# \u2028gyroscope_noise_density: 1.0e-12\n# IMU", 1), "character"),
        (text.replace("# IMU", "#\x85x: 1\n# IMU", 1), "character"),
        (text + " # indented\n", "unexpected line"),
        (text + "extra_key: 1.0\n", "unexpected line"),
        (re.sub(r"^update_rate: .*$", "update_rate: 1e+16", text, flags=re.M), "not a float"),
        (re.sub(r"^gyroscope_random_walk: .*\n", "", text, flags=re.M), "no gyroscope_random"),
        (re.sub(r"^rostopic: .*$", 'rostopic: "/a b"', text, flags=re.M), "rostopic"),
    ]:
        with pytest.raises(ThermocalInputError, match=words):
            check_kalibr_yaml(bad)


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("a\nb", "a\\x0ab"),
        ("a\r\n", "a\\x0d\\x0a"),
        ("a\u2028b\u2029", "a\\u2028b\\u2029"),
        ("a\x85\x00", "a\\x85\\x00"),
        ("\ufeffa\u202e", "\\ufeffa\\u202e"),
        ("20 °C σ", "20 °C σ"),
        ("\U000e0001", "\\U000e0001"),
    ],
)
def test_one_line_escapes_every_line_break(text: str, expected: str) -> None:
    """Every character YAML 1.1 (§5.4: LF, CR, NEL, LS, PS) or Python's ``splitlines``
    (also VT, FF, FS, GS, RS) breaks a line at, and the invisible ones."""
    got = one_line(text)
    assert got == expected
    assert len(got.splitlines()) <= 1 and one_line(got) == got


# --- C: the comment gate's two survivors -----------------------------------------------------

needs_cc = pytest.mark.skipif(find_compiler() is None, reason="no C compiler on this machine")
C_NAMES = ("gx ???/", "gy ?? \\", "gz ?????/ \\ x")
"""``???/``: escaping ``??`` once leaves ``? ??/``, a trigraph (a backslash: C99 5.2.1.1);
a backslash and blanks at a line's end: gcc splices the lines (C99 5.1.1.2 phase 2; gcc
accepts blanks between, with a warning)."""


def _cc(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [str(find_compiler()), *args], cwd=cwd, capture_output=True, text=True, check=False
    )


@needs_cc
def test_a_backslash_and_blanks_is_a_splice_for_gcc_and_the_backstop_refuses_it(
    tmp_path: Path,
) -> None:
    """The reference is the compiler: ``// x \\␠␠⏎int INJECTED;`` loses its second line."""
    src = "// a comment \\  \nint INJECTED;\nint kept;\n"
    (tmp_path / "s.c").write_text(src)
    proc = _cc("-std=c99", "-E", "-P", "s.c", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "INJECTED" not in proc.stdout and "kept" in proc.stdout
    with pytest.raises(ThermocalInputError, match="backslash at the end of a line"):
        check_generated_c(src)
    with pytest.raises(ThermocalInputError, match="backslash at the end of a line"):
        check_generated_c("/* x \\   \n */\nint a;\n")


@needs_cc
def test_trigraphs_and_splices_in_channel_names_give_inert_c(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    n = 600
    t = np.arange(n, dtype=np.float64)
    temp = 10.0 + 30.0 * t / (n - 1)
    rng = np.random.default_rng(5)
    cols = {"time": t, "T1": temp}
    for i, name in enumerate(C_NAMES):
        cols[name] = 0.5 * i + 0.02 * (temp - 25.0) + rng.normal(0.0, 0.01, n)
    data = tmp_path / "run.parquet"
    pq.write_table(pa.table(cols), data)
    cal = tmp_path / "cal.json"
    code, _, err = _run(
        capsys, "fit", str(data), "--model", "poly", "--order", "2", "--signal",
        ",".join(C_NAMES), "--temps", "T1", "--signal-unit", "deg/h", "--temp-unit", "degC",
        "--time-unit", "s", "-o", str(cal),
    )  # fmt: skip
    assert code == 0, err
    cdir = tmp_path / "c"
    code, _, err = _run(capsys, "export-c", str(cal), "-o", str(cdir), "--name", "imu")
    assert code == 0, err
    for f in (cdir / "imu.h", cdir / "imu.c"):
        text = f.read_text(encoding="ascii")
        assert not re.search(r"\?\?[=/'()!<>-]", text), f"{f.name}: a trigraph"
        assert not re.search(r"\\[ \t]*\n", text), f"{f.name}: a line splice"
    proc = _cc(
        "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-trigraphs", "-c", "imu.c",
        "-o", "imu.o", cwd=cdir,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr


# --- JSON and TOML nested 100 000 deep -------------------------------------------------------

DEEP = "[" * 100_000 + "]" * 100_000
FERRARIS = Path(__file__).parents[1] / "data" / "imucal_ferraris" / "example_ferraris_session.csv"


def test_deeply_nested_poses_json_is_refused_naming_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    poses = tmp_path / "poses.json"
    poses.write_text(DEEP)
    big = tmp_path / "big.json"
    big.write_text('{"x": ' + "9" * 5000 + "}")  # Python's 4300-digit limit: a ValueError
    for f in (poses, big):
        before = _digest([f, FERRARIS])
        code, _, err = _run(
            capsys, "multipos", str(FERRARIS), "-o", str(tmp_path / "c.json"), "--rate",
            "102.4", "--accel", "acc_x,acc_y,acc_z", "--gyro", "gyr_x,gyr_y,gyr_z",
            "--gravity", "9.81", "--accel-unit", "m/s^2", "--gyro-unit", "rad/s",
            "--poses", str(f),
        )  # fmt: skip
        assert code == 2, err
        assert _error_line(err).startswith(f"error: {f}: "), err
        assert _digest([f, FERRARIS]) == before
        assert not (tmp_path / "c.json").exists()


def test_deeply_nested_sidecar_is_refused_naming_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    data = tmp_path / "run.csv"
    data.write_text("time,gx\n0,1\n1,2\n2,3\n")
    side = tmp_path / "run.csv.meta.json"
    side.write_text(DEEP)
    code, _, err = _run(capsys, "inspect", str(data))
    assert code == 2, err
    assert _error_line(err).startswith(f"error: {side}: "), err


def test_deeply_nested_parquet_metadata_is_refused_naming_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from thermocal.recording import META_KEY

    data = tmp_path / "run.parquet"
    table = pa.table({"time": np.arange(3.0), "gx": np.arange(3.0)})
    pq.write_table(table.replace_schema_metadata({META_KEY: DEEP}), data)
    code, _, err = _run(capsys, "inspect", str(data))
    assert code == 2, err
    assert _error_line(err).startswith(f"error: {data}: "), err


@pytest.mark.parametrize("command", [["fleet"], ["station", "check"]])
def test_deeply_nested_toml_configuration_is_refused_naming_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], command: list[str]
) -> None:
    cfg = tmp_path / "deep.toml"
    cfg.write_text("a = " + DEEP)
    extra = ["-o", str(tmp_path / "out")] if command == ["fleet"] else []
    code, _, err = _run(capsys, *command, str(cfg), *extra)
    assert code == 2, err
    assert _error_line(err).startswith(f"error: {cfg}: "), err
    assert not (tmp_path / "out").exists()


# --- the sweep: every other generated file a name reaches -----------------------------------

SIGNAL = "g <script>alert(1)</script> \"q\" 'r' `b` $x^2$ %s %n \u2028 */ /* ??/\n# x"
TEMP = "T1 <b>x</b> $\\frac$ \u0085\r\nz"
SENSOR = 'SN <script>x</script>\n"1" $\\frac$'


def _chamber_run(path: Path, signal: str, temp: str, seed: int) -> Path:
    """1200 s at 1 Hz, a quadratic temperature dependence, any column names."""
    n = 1200
    t = np.arange(n, dtype=np.float64)
    temp_c = 25.0 + 15.0 * np.sin(2 * np.pi * t / n * 1.3)
    rng = np.random.default_rng(seed)
    y = 0.5 + 0.02 * (temp_c - 25.0) + 1e-3 * (temp_c - 20.0) ** 2 + rng.normal(0, 0.01, n)
    pq.write_table(pa.table({"time": t, temp: temp_c, signal: y}), path)
    return path


def _html_structure(text: str) -> tuple[list[tuple[str, tuple[str, ...]]], list[str]]:
    """The element tags (with their attribute names) and the text of an HTML page, as a
    browser's tokenizer sees them (the standard library's ``html.parser``)."""
    from html.parser import HTMLParser

    tags: list[tuple[str, tuple[str, ...]]] = []
    data: list[str] = []

    class P(HTMLParser):
        def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
            tags.append((tag, tuple(sorted(a for a, _ in attrs))))

        def handle_data(self, d: str) -> None:
            data.append(d)

    P(convert_charrefs=True).feed(text)
    return tags, data


def _report(
    tmp: Path, capsys: pytest.CaptureFixture[str], signal: str, temp: str, sensor: str
) -> str:
    """fit → validate → compensate → report, the order a user runs them; every input
    hashed before and after; the report's text."""
    m = _chamber_run(tmp / "m.parquet", signal, temp, 1)
    v = _chamber_run(tmp / "v.parquet", signal, temp, 2)
    cal, val, comp, html = (tmp / n for n in ("cal.json", "val.json", "c.csv", "r.html"))
    before = _digest([m, v])
    code, _, err = _run(
        capsys, "fit", str(m), "--model", "poly", "--order", "2", "--signal", signal,
        "--temps", temp, "--signal-unit", "deg/h", "--temp-unit", "degC", "--time-unit", "s",
        "-o", str(cal),
    )  # fmt: skip
    assert code == 0, err
    code, out, err = _run(
        capsys, "validate", str(cal), str(v), "--modeling", str(m), "--time-unit", "s", "--json"
    )
    assert code == 0, err
    val.write_text(out)
    code, _, err = _run(capsys, "compensate", str(cal), str(v), "-o", str(comp), "--time-unit", "s")
    assert code == 0, err
    # CSV: the reader gets back the names as they were
    import csv

    with comp.open(newline="", encoding="utf-8") as fh:
        header = next(csv.reader(fh))
    assert header[0] == "time" and set(header[1:]) >= {temp, signal, f"{signal}_comp"}
    code, _, err = _run(
        capsys, "report", "--model", str(cal), "--recording", str(v), "--validation", str(val),
        "--modeling", str(m), "--time-unit", "s", "--sensor", sensor, "--title", sensor,
        "-o", str(html),
    )  # fmt: skip
    assert code == 0, err
    assert not any(ln.startswith("error") for ln in err.splitlines())
    assert _digest([m, v]) == before
    return html.read_text(encoding="utf-8")


def test_hostile_names_leave_reports_csv_and_json_inert(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The same runs under plain and under hostile names (a ``<script>``, quotes, TeX that
    matplotlib's mathtext refuses, line breaks): the HTML has the same elements and
    attributes (``html.parser``), the hostile names appear as text, whole; the model file
    (JSON) and the compensated CSV give the names back as they were."""
    (tmp_path / "plain").mkdir()
    (tmp_path / "hostile").mkdir()
    plain = _report(tmp_path / "plain", capsys, "gx", "T1", "SN1")
    hostile = _report(tmp_path / "hostile", capsys, SIGNAL, TEMP, SENSOR)
    p_tags, _ = _html_structure(plain)
    h_tags, h_data = _html_structure(hostile)
    assert h_tags == p_tags
    assert [t for t, _ in h_tags].count("script") == 1  # the page's own load check
    text = "".join(h_data)
    assert SIGNAL in text and "<script>x</script>" in text
    import json

    def strings(x: object) -> list[str]:
        if isinstance(x, dict):
            return [s for k, v in x.items() for s in [k, *strings(v)]]
        if isinstance(x, list):
            return [s for v in x for s in strings(v)]
        return [x] if isinstance(x, str) else []

    doc = json.loads((tmp_path / "hostile" / "cal.json").read_text(encoding="utf-8"))
    assert SIGNAL in strings(doc) and TEMP in strings(doc)


def test_tex_in_a_column_name_is_plotted_as_text(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``allan --plot`` and its ``--dynamic`` heat map title the figure with the column:
    matplotlib's mathtext raised ValueError on ``$\\frac$`` (exit 1)."""
    data = _chamber_run(tmp_path / "f.parquet", "g $\\frac$", "T1", 3)
    png = tmp_path / "a.png"
    code, _, err = _run(
        capsys, "allan", str(data), "--signal", "g $\\frac$", "--signal-unit", "deg/h",
        "--time-unit", "s", "--plot", str(png), "--dynamic", "200",
    )  # fmt: skip
    assert code == 0, err
    pngs = sorted(tmp_path.glob("*.png"))
    assert len(pngs) == 2 and all(p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for p in pngs)


@pytest.mark.parametrize("uid", ["u1\n", "u1\n\n", "u1\r", "../u1", "u 1", "u1/..", ""])
def test_a_fleet_unit_id_that_is_no_directory_name_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], uid: str
) -> None:
    """A unit's id names its folder (``units/<id>``) and its row in the summary: ``u1⏎``
    passed ``^[A-Za-z0-9][A-Za-z0-9._-]*$`` (``$`` matches before a final newline) and made
    a folder whose name holds a newline."""
    import json

    data = _chamber_run(tmp_path / "m.parquet", "gx", "T1", 1)
    cfg = tmp_path / "fleet.toml"
    cfg.write_text(
        '[fit]\nmodel = "poly"\norder = 2\nsignal = "gx"\ntemps = "T1"\n'
        'signal-unit = "deg/h"\ntemp-unit = "degC"\ntime-unit = "s"\n'
        f"[[unit]]\nid = {json.dumps(uid)}\nmodeling = {json.dumps(str(data))}\n"
    )
    out = tmp_path / "out"
    code, _, err = _run(capsys, "fleet", str(cfg), "-o", str(out))
    assert code == 2, err
    line = _error_line(err)
    assert line.startswith(f"error: {cfg}") and repr(uid) in line, line
    assert not out.exists()


@pytest.mark.parametrize("sid", ["imu\n", "imu\r", "im u", "imu-1", ""])
def test_a_station_sensor_id_that_is_no_stream_name_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], sid: str
) -> None:
    """A sensor's id names its stream files (``<id>-0000.parquet``) and its entry in
    ``station.json``; ``imu⏎`` passed ``^[A-Za-z0-9][A-Za-z0-9_]*$`` (``$`` matches before a
    final newline).  Refused while the configuration is read, before any port is opened."""
    import json

    cfg = tmp_path / "station.toml"
    cfg.write_text(
        'part_s = 0.5\n[chamber]\ndriver = "modbus-tcp"\nhost = "127.0.0.1"\nport = 1\n'
        "setpoint_register = 300\ntemperature_register = 100\n"
        f"[[sensor]]\nid = {json.dumps(sid)}\ndevice = {json.dumps(str(tmp_path / 'tty'))}\n"
        'baud = 115200\nnames = ["gx", "temp"]\nunits = ["deg/s", "degC"]\nrate_hz = 50\n'
    )
    code, _, err = _run(capsys, "station", "check", str(cfg))
    assert code == 2, err
    line = _error_line(err)
    assert line.startswith(f"error: {cfg}") and repr(sid) in line, line


TRIAD = (
    "g\n1\t1\tTC_G0_ID\t0\t6\n# x",
    "g <script> y",
    "g \u2028INS_TCAL1_ENABLE 0 z",
    "a\rINS_TCAL1_ENABLE 0 x",
    'a "q" %s `b` y',
    "a \x85 # */ z",
)
PARAM_LINE = {
    "px4": re.compile(r"1\t1\t[A-Z][A-Z0-9_]*\t-?[0-9][0-9.e+-]*\t(6|9)"),
    "ardupilot": re.compile(r"[A-Z][A-Z0-9_]* -?[0-9][0-9.e+-]*"),
}
"""A parameter line of QGroundControl's file (vehicle, component, name, value, MAVLink type)
and of ArduPilot's ``.parm`` (name, value): names are firmware names, never a column's."""


@pytest.mark.parametrize("fmt", ["px4", "ardupilot"])
def test_hostile_channel_names_never_reach_a_parameter_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], fmt: str
) -> None:
    """A gyro and an accelerometer triad under hostile names, fitted and exported: every
    line of the file is a comment or a parameter line of the firmware's grammar, and the
    parameters are those of the same calibration under plain names."""
    n = 400
    t = np.arange(n, dtype=float)
    temp = 10.0 + 30.0 * t / (n - 1)
    rng = np.random.default_rng(26)
    values = [c + 0.01 * (temp - 25.0) + rng.normal(0.0, 0.001, n) for c in (0.1, 0.2, 0.3)]
    values += [c + 0.3 * (temp - 25.0) + rng.normal(0.0, 0.5, n) for c in (5.0, -3.0, 1000.0)]
    texts = {}
    for label, names in (("plain", PLAIN), ("hostile", TRIAD)):
        d = tmp_path / label
        d.mkdir()
        pq.write_table(
            pa.table({"time": t, "T1": temp, **dict(zip(names, values, strict=True))}), d / "r.pq"
        )
        code, _, err = _run(
            capsys, "fit", str(d / "r.pq"), "--model", "poly", "--order", "3", "--signal",
            ",".join(names), "--signal-unit", "deg/s,deg/s,deg/s,mg,mg,mg", "--time-unit", "s",
            "--temps", "T1", "--temp-unit", "degC", "--gravity-axis", "+z", "--gravity",
            "9.80665", "-o", str(d / "cal.json"),
        )  # fmt: skip
        assert code == 0, err
        out = d / "params.txt"
        code, _, err = _run(
            capsys, "export-params", str(d / "cal.json"), "--format", fmt, "--gyro",
            ",".join(names[:3]), "--accel", ",".join(names[3:]), "-o", str(out),
        )  # fmt: skip
        assert code == 0, err
        texts[label] = out.read_text(encoding="utf-8")
    lines = texts["hostile"].split("\n")
    assert lines[-1] == "" and not re.search("[\r\x85\u2028\u2029]", texts["hostile"])
    for ln in lines[:-1]:
        assert ln.startswith("#") or PARAM_LINE[fmt].fullmatch(ln), ln
    assert texts["hostile"] == texts["plain"]


def test_hostile_names_in_the_json_noise_model_come_back_whole(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``noise --format json``: every axis under its own name as written in the file."""
    import json

    data = _imu(tmp_path / "imu.parquet", HOSTILE_A)
    out = tmp_path / "noise.json"
    code, _, err = _run(capsys, *_noise(data, out, HOSTILE_A, "--format", "json"))
    assert code == 0, err
    doc = json.loads(out.read_text(encoding="utf-8"))
    assert list(doc["axes"]) == list(HOSTILE_A)
    assert doc["kalibr_axis"]["gyroscope_noise_density"] in HOSTILE_A[:3]
    assert doc["kalibr"]["gyroscope_noise_density"] == pytest.approx(max(GYRO_DENSITY), rel=0.15)


def test_an_output_name_with_a_newline_the_system_refuses_gives_one_error_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A name too long for the file system (ENAMETOOLONG, a user's error) holding a newline:
    the ``error:`` line named it raw and spread over two lines."""
    data = _chamber_run(tmp_path / "m.parquet", "gx", "T1", 1)
    out = tmp_path / ("x\ny" + "a" * 300 + ".json")
    code, _, err = _run(
        capsys, "fit", str(data), "--model", "poly", "--order", "2", "--signal", "gx",
        "--temps", "T1", "--signal-unit", "deg/h", "--temp-unit", "degC", "--time-unit", "s",
        "-o", str(out),
    )  # fmt: skip
    assert code == 2, err
    line = _error_line(err)
    assert "x ya" in line, line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.parquet"]
