"""``thermocal simulate tumble`` and ``thermocal tumble``: K2 and K_ip against the
simulator's truth through the command line, the input left untouched, and the one-line
refusals of what a user can get wrong (NaN angles, one angle, the four quadrants that cannot
separate the second harmonic, time running backwards, no angle at all)."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import pytest

from bag_writer import NS, Topic, write_bag
from chamber_logs import air_c, write_log
from thermocal.cli import main
from thermocal.recording import Recording
from thermocal.tumble.simulate import simulate_tumble
from thermocal.writers import write_recording

G_MG = 9.80665e-3
"""One mg in m/s² (standard gravity 9.80665 m/s², CGPM 1901)."""


def _sha(p: Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest()


def _one_line_error(capsys: pytest.CaptureFixture[str], *words: str) -> str:
    err = [ln for ln in capsys.readouterr().err.strip().splitlines() if ln[:9] != "warning: "]
    assert len(err) == 1 and err[0].startswith("error: "), err
    for w in words:
        assert w in err[0], err[0]
    return err[0]


@pytest.fixture(scope="module")
def sim(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    d = tmp_path_factory.mktemp("tb")
    assert main(["simulate", "tumble", "--seed", "3", "-o", str(d / "tb.csv"),
                 "--truth", str(d / "truth.json")]) == 0  # fmt: skip
    return d / "tb.csv", json.loads((d / "truth.json").read_text())["files"][0]


def test_simulated_tumble_recovered_through_the_cli(
    sim: tuple[Path, dict], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path, truth = sim
    before = _sha(path)
    out = tmp_path / "res.json"
    assert main(["tumble", str(path), "--angle-column", "angle", "-o", str(out), "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert json.loads(out.read_text()) == res and _sha(path) == before
    assert res["mode"] == "stations" and len(res["stations"]) == 24
    assert res["units"]["k2"] == "mg/g^2" and res["output_unit"] == "mg"
    for n in ("k0", "k1", "delta_o", "k2", "k_ip"):
        assert abs(res["coefficients"][n] - truth[n]) < 3 * res["sigmas"][n], n
    assert res["significant"]["k2"] and res["significant"]["k_ip"]
    k2n = res["normalised"]["k2_g_per_g2"]
    assert abs(k2n["value"] - truth["k2"] / truth["k1"]) < 3 * k2n["sigma"]
    # the text: K2 in µg/g² per K1
    assert main(["tumble", str(path), "--angle-column", "angle"]) == 0
    assert "µg/g²" in capsys.readouterr().out


def test_continuous_tumble_through_the_cli(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    p = tmp_path / "tc.csv"
    assert main(["simulate", "tumble", "--turns", "-o", str(p), "--truth",
                 str(tmp_path / "t.json"), "--rate-hz", "10"]) == 0  # fmt: skip
    truth = json.loads((tmp_path / "t.json").read_text())["files"][0]
    capsys.readouterr()
    for extra in (["--turn-rate", "2"], ["--angle-column", "angle"]):
        assert main(["tumble", str(p), *extra, "--json"]) == 0
        res = json.loads(capsys.readouterr().out)
        assert res["mode"] == "continuous" and res["stations"] == []
        for n in ("k2", "k_ip"):
            assert abs(res["coefficients"][n] - truth[n]) < 3 * res["sigmas"][n], n


def _write(tmp: Path, angles: np.ndarray, *, time: np.ndarray | None = None) -> Path:
    n = angles.size
    t = np.arange(n) * 0.1 if time is None else time
    y = 1000.0 * np.cos(np.deg2rad(np.nan_to_num(angles))) + 0.01 * np.sin(np.arange(n))
    rec = Recording.from_arrays(t, {"accel": y}, signal_unit="mg", other={"angle": angles},
                                other_units={"angle": "deg"})  # fmt: skip
    p = tmp / "bad.csv"
    write_recording(rec, p)
    return p


def _stations(angles: list[float], per: int = 50) -> np.ndarray:
    return np.repeat(np.asarray(angles, float), per)


@pytest.mark.parametrize(
    ("case", "words"),
    [
        ("nan", ("angle column 'angle' are not numbers", "--turn-rate")),
        ("one", ("1 distinct angle", "K2 and K_ip", "--harmonics")),
        ("quadrants", ("4 distinct angle", "K2 and K_ip", "24 stations")),
        ("arc", ("gap of", "spread the angles")),
        ("backwards", ("time",)),
        ("no-angle", ("--angle-column", "--turn-rate")),
        ("both", ("--angle-column", "--turn-rate")),
        ("missing", ("no column 'nope'", "--angle-column")),
        ("harmonics", ("--harmonics",)),
    ],
)
def test_what_a_user_gets_wrong_is_one_line(
    case: str, words: tuple[str, ...], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    a = _stations(list(np.arange(0.0, 360.0, 30.0)))
    args = ["--angle-column", "angle"]
    if case == "nan":
        a[100] = np.nan
    elif case == "one":
        a = _stations([0.0], 300)
    elif case == "quadrants":
        a = _stations([0.0, 90.0, 180.0, 270.0] * 3)
    elif case == "arc":
        a = _stations(list(np.arange(0.0, 60.0, 5.0)))
    elif case == "no-angle":
        args = []
    elif case == "both":
        args += ["--turn-rate", "2"]
    elif case == "missing":
        args = ["--angle-column", "nope"]
    elif case == "harmonics":
        args += ["--harmonics", "1"]
    t = np.arange(a.size) * 0.1
    if case == "backwards":
        t[300:] -= 5.0
    p = _write(tmp_path, a, time=t)
    before = _sha(p)
    assert main(["tumble", str(p), "--min-station", "1", "--settle", "0.5", *args]) == 2
    _one_line_error(capsys, *words)
    assert _sha(p) == before


def test_a_rate_unit_is_not_an_accelerometer(
    sim: tuple[Path, dict], capsys: pytest.CaptureFixture[str]
) -> None:
    path, _ = sim
    assert main(["tumble", str(path), "--angle-column", "angle", "--accel-unit", "deg/s"]) == 2
    _one_line_error(capsys, "a rate", "--accel-unit")


def test_stations_simulated_in_the_library_equal_the_cli(tmp_path: Path) -> None:
    rec, _ = simulate_tumble(np.random.default_rng(0), stations=8, dwell_s=4.0)
    p = tmp_path / "s.csv"
    write_recording(rec, p)
    assert main(["tumble", str(p), "--angle-column", "angle", "-o", str(tmp_path / "r.json")]) == 0
    res = json.loads((tmp_path / "r.json").read_text())
    assert [round(s["angle_deg"], 6) for s in res["stations"]] == [45.0 * k for k in range(8)]


def test_the_report_page(
    sim: tuple[Path, dict], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path, _ = sim
    page = tmp_path / "tumble.html"
    assert main(["tumble", str(path), "--angle-column", "angle", "--report", str(page)]) == 0
    html = page.read_text(encoding="utf-8")
    assert 'id="fig-tumble-harmonics" src="data:image/png;base64,' in html
    assert "K2 second order" in html
    capsys.readouterr()
    same = ["-o", str(tmp_path / "x.html"), "--report", str(tmp_path / "x.html")]
    assert main(["tumble", str(path), "--angle-column", "angle", *same]) == 2
    _one_line_error(capsys, "-o and --report")


def test_the_chamber_log_gives_the_test_temperature(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A tumble run 2000 s into the chamber log's clock, on its 20 → 60 °C ramp: the
    temperature and each station's from the log (°F, every 10 s), against the air the log
    was written from (tests/helpers/chamber_logs)."""
    rec, _ = simulate_tumble(np.random.default_rng(1), stations=12, dwell_s=10.0)
    p = tmp_path / "tb.csv"
    write_recording(rec, p)
    log = write_log(tmp_path / "log.csv", style="hh:mm:ss", period_s=10.0, unit="degF")
    chamber = ["--chamber-log", f"{log}:Chamber PV", "--chamber-offset", "2000"]
    assert main(["tumble", str(p), "--angle-column", "angle", *chamber, "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    t = rec.time_s
    air = air_c(2000.0 + t)  # the air at each sample
    temp = res["temperature"]
    assert temp["column"] == "chamber"
    assert temp["mean_c"] == pytest.approx(float(np.mean(air)), abs=0.01)
    assert (temp["min_c"], temp["max_c"]) == (
        pytest.approx(float(air.min()), abs=0.01),
        pytest.approx(float(air.max()), abs=0.01),
    )
    assert len(res["stations"]) == 12
    for s in res["stations"]:
        kept = (t >= s["start_s"]) & (t <= s["end_s"])
        assert s["temp_c"] == pytest.approx(float(np.mean(air[kept])), abs=0.01)
    # the same through --temps chamber, in the text and on the page
    page = tmp_path / "tb.html"
    args = ["tumble", str(p), "--angle-column", "angle", "--temps", "chamber", *chamber]
    assert main([*args, "--report", str(page)]) == 0
    said = f"temperature (chamber): {temp['mean_c']:.2f} °C mean"
    assert said in capsys.readouterr().out and said in page.read_text(encoding="utf-8")
    # without a log: no temperature; a chamber option alone is refused
    assert main(["tumble", str(p), "--angle-column", "angle", "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["temperature"] is None and res["stations"][0]["temp_c"] is None
    assert main(["tumble", str(p), "--angle-column", "angle", "--chamber-offset", "2000"]) == 2
    _one_line_error(capsys, "--chamber-offset applies with --chamber-log")
    # --temps chamber without a log: told where that temperature comes from
    assert main(["tumble", str(p), "--angle-column", "angle", "--temps", "chamber"]) == 2
    _one_line_error(capsys, "no column 'chamber'", "chamber log's temperature",
                    "--chamber-log FILE:CHANNEL")  # fmt: skip


def test_a_continuous_tumble_from_a_bag_topic_and_its_stamps(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A continuous tumble at 2 °/s logged in a ROS bag beside another IMU: --topic picks
    it; its receive stamps run at half the header stamps' pace (a recorder's clock), so
    with --stamp receive the head turns at 1 °/s of that clock."""
    rec, truth = simulate_tumble(np.random.default_rng(2), turn_rate_dps=2.0, rate_hz=10.0)
    n = rec.n_samples
    header = (1_700_000_000 * NS + np.round(rec.time_s * NS)).astype(np.int64)
    receive = header[0] + 2 * (header - header[0])
    imu = np.zeros((n, 6))
    imu[:, 5] = rec.columns["accel"] * G_MG  # mg → m/s²
    other = np.zeros((n, 6))
    other[:, 5] = 9.80665
    bag = write_bag(tmp_path / "tumble.bag", "ros1", [
        Topic("/imu_head", "sensor_msgs/msg/Imu", header, receive, imu),
        Topic("/imu_base", "sensor_msgs/msg/Imu", header, receive, other),
    ])  # fmt: skip
    base = ["tumble", str(bag), "--accel", "accel_z", "--topic", "/imu_head", "--json"]
    for extra in (["--turn-rate", "2"], ["--stamp", "receive", "--turn-rate", "1"]):
        assert main([*base, *extra]) == 0, capsys.readouterr().err
        res = json.loads(capsys.readouterr().out)
        assert res["output_unit"] == "m/s^2" and res["mode"] == "continuous"
        for k in ("k0", "k1", "k2", "k_ip"):
            want = truth[k] * G_MG
            assert abs(res["coefficients"][k] - want) < 3 * res["sigmas"][k], (extra, k)
    # the receive stamps at 2 °/s: the angles twice what they were, the fit far off
    assert main([*base, "--stamp", "receive", "--turn-rate", "2"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert abs(res["coefficients"]["k1"] - truth["k1"] * G_MG) > 10 * res["sigmas"]["k1"]
    # two Imu topics and none named: the refusal names --topic
    assert main(["tumble", str(bag), "--accel", "accel_z", "--turn-rate", "2"]) == 2
    _one_line_error(capsys, "--topic")


@pytest.mark.parametrize("unit", ["ug", "counts"])
def test_an_accel_unit_against_the_file_is_said_as_typed(
    unit: str, sim: tuple[Path, dict], capsys: pytest.CaptureFixture[str]
) -> None:
    path, _ = sim  # the file says mg (and its values are not whole counts)
    assert main(["tumble", str(path), "--angle-column", "angle", "--accel-unit", unit]) == 0
    err = capsys.readouterr().err
    assert f"--accel-unit {unit} contradicts the file's metadata" in err, err
    assert "--signal-unit" not in err


def test_tumble_and_ratetable_read_files_as_fit_does() -> None:
    """The reading options (a text log's layout, a flight log's or bag's topic and stamps,
    the chamber's log) of fit, on the tumble and rate-table commands too."""
    import typer

    import thermocal.cli

    thermocal.cli._register()
    root = typer.main.get_command(thermocal.cli.app)
    commands = root.commands  # type: ignore[attr-defined]

    def opts(name: str) -> set[str]:
        return {o for p in commands[name].params for o in p.opts}

    reading = {"--time", "--time-unit", "--names", "--topic", "--sensor", "--stamp", "--rate",
               "--on-bad-lines", "--delimiter", "--decimal", "--chamber-log", "--chamber-offset",
               "--chamber-unit", "--chamber-date", "--chamber-date-order", "--chamber-drift",
               "--chamber-tz"}  # fmt: skip
    assert reading <= opts("fit")
    for name in ("tumble", "ratetable"):
        assert reading <= opts(name), (name, reading - opts(name))
