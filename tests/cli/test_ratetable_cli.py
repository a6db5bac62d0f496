"""``thermocal simulate ratetable`` and ``thermocal ratetable``: the figures against the
simulator's truth (numpy.polyfit on its noise-free plateau outputs), the plateaus found from
the output with ``--rates``, and the one-line refusals of what a user can get wrong."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import pytest

from bag_writer import NS, Topic, write_bag
from thermocal.cli import main
from thermocal.ratetable.simulate import simulate_ladder
from thermocal.writers import write_recording

LADDER = (-200.0, -50.0, -10.0, 0.0, 10.0, 50.0, 200.0)


def _sha(p: Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest()


def _one_line_error(capsys: pytest.CaptureFixture[str], *words: str) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: "), err
    for w in words:
        assert w in err[0], err[0]
    return err[0]


@pytest.fixture(scope="module")
def sim(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    d = tmp_path_factory.mktemp("rt")
    assert main(["simulate", "ratetable", "--runs", "3", "-o", str(d / "rt"),
                 "--truth", str(d / "truth.json")]) == 0  # fmt: skip
    return d, json.loads((d / "truth.json").read_text())


@pytest.fixture(scope="module")
def ladder_csv(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    """A ladder without a rate column: the plateaus come from the output."""
    d = tmp_path_factory.mktemp("rt2")
    rec, truth = simulate_ladder(np.random.default_rng(7), rates_dps=LADDER, dwell_s=10.0,
                                 rate_hz=50.0, cubic_ppm=300.0, asymmetry_ppm=-250.0)  # fmt: skip
    del rec.columns["table_rate"]
    path = d / "ladder.csv"
    write_recording(rec, path)
    return path, truth


def test_simulated_ladders_recovered_through_the_cli(
    sim: tuple[Path, dict], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    d, truth = sim
    files = sorted(str(p) for p in (d / "rt").glob("*.csv"))
    before = [_sha(Path(f)) for f in files]
    out = tmp_path / "res.json"
    args = ["ratetable", *files, "--rate-column", "table_rate", "--temps", "temp", "-o", str(out)]
    assert main([*args, "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert json.loads(out.read_text()) == res
    assert [_sha(Path(f)) for f in files] == before
    assert len(res["ladders"]) == 3
    by_file = {Path(t["file"]).name: t for t in truth["files"]}
    for ld, f in zip(res["ladders"], res["files"], strict=True):
        tr = by_file[Path(f).name]
        w = np.array([p["rate_dps"] for p in tr["plateaus"]])
        y = np.array(tr["outputs"])
        keep = np.ones(w.size, bool)
        keep[30] = False  # the plateau the operator cut short (4 s, below --min-plateau)
        k = np.polyfit(w[keep], y[keep], 1)[0]
        assert abs(ld["scale_factor"] - k) < 4 * ld["scale_factor_sigma"]
        assert ld["asymmetry_ppm"]["value"] > 0  # positive asymmetry and quadratic term
        thr = ld["threshold_dps"]
        assert thr["above_dps"] < tr["dead_zone_dps"] <= thr["value"]  # 0.01 < 0.015 ≤ 0.02
        assert ld["repeatability_ppm"]["value"] is not None  # up and back down
    tc = res["temperature_coefficient"]
    want = truth["files"][0]["tc_ppm_per_c"] / (1 + 40e-6 * (tc["tref_c"] - 25.0))
    assert abs(tc["ppm_per_c"] - want) < 4 * tc["sigma_ppm_per_c"]
    assert all(len(p["dropped"]) == 1 for p in res["plateaus"])


def test_text_output_is_the_spec_sheet(
    sim: tuple[Path, dict], capsys: pytest.CaptureFixture[str]
) -> None:
    d, _ = sim
    f = sorted((d / "rt").glob("*.csv"))[1]
    assert main(["ratetable", str(f), "--rate-column", "table_rate"]) == 0
    out = capsys.readouterr().out
    for line in ("scale factor", "scale-factor nonlinearity", "asymmetry", "input threshold",
                 "resolution", "repeatability", "per rate", "settling"):  # fmt: skip
        assert line in out


def test_plateaus_from_the_output_with_rates(
    ladder_csv: tuple[Path, dict], capsys: pytest.CaptureFixture[str]
) -> None:
    path, truth = ladder_csv
    rates = ",".join(f"{r:g}" for r in LADDER)
    assert main(["ratetable", str(path), f"--rates={rates}", "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    ld = res["ladders"][0]
    w = np.array(LADDER)
    k = np.polyfit(w, np.array(truth["outputs"]), 1)[0]
    assert abs(ld["scale_factor"] - k) < 4 * ld["scale_factor_sigma"]
    assert ld["asymmetry_ppm"]["value"] < 0  # the sign of the simulated asymmetry
    assert res["plateaus"][0]["source"] == "output"
    for p, t in zip(res["plateaus"][0]["plateaus"], truth["plateaus"], strict=True):
        assert t["start_s"] <= p["start_s"] <= t["start_s"] + 2.0  # settling left out
        assert p["end_s"] <= t["end_s"] + 0.5


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        (["--rates=-200,-50,0,50,200"], ("plateaus found", "--rates")),
        (["--rates=200,50,10,0,-10,-50,-200,5"], ("--rates",)),
        (["--rates=-200,-50,10,0,-10,50,200"], ("--rates",)),
        (["--rates=-3.49,-0.873,-0.175,0,0.175,0.873,3.49"], ("rad/s", "--gyro-unit")),
        ([], ("--rates", "--rate-column", "--schedule")),
        (["--rate-column", "nope"], ("nope", "--rate-column")),
        (["--rates=-200,-50,-10,0,10,50,200", "--min-plateau", "500"], ("--min-plateau",)),
        (["--rates=-200,-50,-10,0,10,50,200", "--settle", "-1"], ("--settle",)),
        (["--rates=-200,x"], ("--rates",)),
    ],
)
def test_user_errors_exit_2_with_one_line(
    ladder_csv: tuple[Path, dict], extra: list[str], words: tuple[str, ...],
    capsys: pytest.CaptureFixture[str],
) -> None:  # fmt: skip
    path, _ = ladder_csv
    before = _sha(path)
    assert main(["ratetable", str(path), *extra]) == 2
    _one_line_error(capsys, *words)
    assert _sha(path) == before


def test_one_direction_refused_unless_asked(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rec, _ = simulate_ladder(np.random.default_rng(3), rates_dps=(0.0, 10.0, 100.0, 300.0),
                             dwell_s=8.0, rate_hz=50.0)  # fmt: skip
    f = tmp_path / "up.csv"
    write_recording(rec, f)
    assert main(["ratetable", str(f), "--rate-column", "table_rate"]) == 2
    _one_line_error(capsys, "only positive rates", "--one-direction")
    assert main(["ratetable", str(f), "--rate-column", "table_rate", "--one-direction"]) == 0
    assert "asymmetry: not computed" in capsys.readouterr().out


def test_several_files_need_temps_and_distinct_temperatures(
    sim: tuple[Path, dict], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    d, _ = sim
    f = sorted((d / "rt").glob("*.csv"))[0]
    assert main(["ratetable", str(f), str(f), "--rate-column", "table_rate"]) == 2
    _one_line_error(capsys, "--temps")
    assert main(["ratetable", str(f), str(f), "--rate-column", "table_rate",
                 "--temps", "temp"]) == 2  # fmt: skip
    _one_line_error(capsys, "two or more temperatures", "--temps")


def test_schedule_and_output_over_input(
    ladder_csv: tuple[Path, dict], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path, truth = ladder_csv
    sched = tmp_path / "sched.csv"
    rows = [f"{p['start_s'] + 1},{p['end_s']},{p['rate_dps']}" for p in truth["plateaus"]]
    sched.write_text("start_s,end_s,rate_dps\n" + "\n".join(rows) + "\n")
    assert main(["ratetable", str(path), "--schedule", str(sched), "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["plateaus"][0]["source"] == "schedule"
    assert len(res["ladders"][0]["rates"]) == len(LADDER)
    before = _sha(path)
    assert main(["ratetable", str(path), "--schedule", str(sched), "-o", str(path)]) == 2
    _one_line_error(capsys)
    assert _sha(path) == before
    sched.write_text("0,10,5,1\n")
    assert main(["ratetable", str(path), "--schedule", str(sched)]) == 2
    _one_line_error(capsys, "start_s,end_s,rate_dps")
    sched.write_text("0,10\n")  # a program of one rate
    assert main(["ratetable", str(path), "--schedule", str(sched)]) == 2
    _one_line_error(capsys, "--schedule", "rate_dps,dwell_s")


def test_reversed_ladder_warns(
    ladder_csv: tuple[Path, dict], capsys: pytest.CaptureFixture[str]
) -> None:
    path, _ = ladder_csv
    rates = ",".join(f"{r:g}" for r in LADDER[::-1])
    assert main(["ratetable", str(path), f"--rates={rates}", "--json"]) == 0
    cap = capsys.readouterr()
    assert json.loads(cap.out)["ladders"][0]["scale_factor"] < 0
    warn = [ln for ln in cap.err.splitlines() if ln.startswith("warning: ")]
    assert len(warn) == 1 and "reverse order" in warn[0] and "--rates" in warn[0]


def test_report_is_a_self_contained_spec_sheet(
    sim: tuple[Path, dict], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    d, _ = sim
    files = sorted(str(p) for p in (d / "rt").glob("*.csv"))
    rep = tmp_path / "rt.html"
    args = ["ratetable", *files, "--rate-column", "table_rate", "--temps", "temp"]
    assert main([*args, "--report", str(rep)]) == 0
    capsys.readouterr()
    html = rep.read_text(encoding="utf-8")
    for fig in ("fig-ratetable-nonlinearity", "fig-ratetable-temperature"):
        assert f'id="{fig}" src="data:image/png;base64,' in html
    assert "scale-factor temperature coefficient" in html and "http" not in html
    assert main([*args, "--report", str(rep), "-o", str(rep)]) == 2
    _one_line_error(capsys, "--report")
    assert main([*args, "--report", files[0]]) == 2
    _one_line_error(capsys)


def test_one_file_with_two_temperatures(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from thermocal.recording import Recording

    rng = np.random.default_rng(11)
    kw = {"rates_dps": LADDER, "dwell_s": 8.0, "rate_hz": 50.0, "tc_ppm_per_c": 100.0}
    a, _ = simulate_ladder(rng, temperature_c=-10.0, **kw)  # type: ignore[arg-type]
    b, _ = simulate_ladder(rng, temperature_c=40.0, **kw)  # type: ignore[arg-type]
    t = np.concatenate([a.time_s, b.time_s + a.time_s[-1] + 600.0])  # a soak between
    cols = {c: np.concatenate([a.columns[c], b.columns[c]]) for c in ("gyro", "table_rate", "temp")}
    rec = Recording.from_arrays(t, {"gyro": cols["gyro"]}, {"temp": cols["temp"]},
                                signal_unit="deg/s", other={"table_rate": cols["table_rate"]},
                                other_units={"table_rate": "deg/s"})  # fmt: skip
    f = tmp_path / "both.csv"
    write_recording(rec, f)
    assert main(["ratetable", str(f), "--rate-column", "table_rate", "--temps", "temp",
                 "--json"]) == 0  # fmt: skip
    res = json.loads(capsys.readouterr().out)
    assert [round(ld["temperature_c"]) for ld in res["ladders"]] == [-10, 40]
    tc = res["temperature_coefficient"]
    want = 100.0 / (1 + 100e-6 * (tc["tref_c"] - 25.0))
    assert abs(tc["ppm_per_c"] - want) < 4 * tc["sigma_ppm_per_c"]
    assert main(["ratetable", str(f), "--rate-column", "table_rate", "--temps", "temp",
                 "--temp-gap", "100", "--json"]) == 0  # fmt: skip
    assert len(json.loads(capsys.readouterr().out)["ladders"]) == 1


def test_correlated_noise_is_said(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rng = np.random.default_rng(5)
    rec, _ = simulate_ladder(rng, rates_dps=LADDER, dwell_s=20.0, rate_hz=50.0, noise_dps=0.001)
    rec.columns["gyro"] = rec.columns["gyro"] + np.cumsum(rng.normal(0.0, 2e-4, rec.n_samples))
    f = tmp_path / "walk.csv"
    write_recording(rec, f)
    assert main(["ratetable", str(f), "--rate-column", "table_rate"]) == 0
    warn = [ln for ln in capsys.readouterr().err.splitlines() if ln.startswith("warning: ")]
    assert len(warn) == 1 and "correlated" in warn[0] and "too small" in warn[0]


def test_ladders_that_differ_between_temperatures_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    files = []
    for t, ladder in ((0.0, LADDER), (40.0, (-200.0, -10.0, 0.0, 10.0, 200.0))):
        rec, _ = simulate_ladder(np.random.default_rng(int(t)), rates_dps=ladder, dwell_s=8.0,
                                 rate_hz=50.0, temperature_c=t)  # fmt: skip
        files.append(tmp_path / f"T{t:+.0f}.csv")
        write_recording(rec, files[-1])
    args = ["ratetable", *map(str, files), "--rate-column", "table_rate", "--temps", "temp"]
    assert main(args) == 2
    _one_line_error(capsys, "do not hold the same rates", "-50, 50", "--temps")


def test_noisy_rate_column_needs_the_rate_tolerance(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rng = np.random.default_rng(9)
    rec, truth = simulate_ladder(rng, rates_dps=LADDER, dwell_s=10.0, rate_hz=50.0,
                                 cubic_ppm=200.0, repeats=2)  # fmt: skip
    rec.columns["table_rate"] = rec.columns["table_rate"] + rng.normal(0, 0.003, rec.n_samples)
    f = tmp_path / "noisy.csv"
    write_recording(rec, f)
    args = ["ratetable", str(f), "--rate-column", "table_rate"]
    assert main(args) == 2
    _one_line_error(capsys, "--rate-tolerance", "--min-plateau")
    assert main([*args, "--rate-tolerance", "0.05", "--json"]) == 0
    ld = json.loads(capsys.readouterr().out)["ladders"][0]
    assert [r["rate_dps"] for r in ld["rates"]] == sorted(LADDER)  # visits rounded together
    assert ld["repeatability_ppm"]["value"] is not None
    w = np.array([p["rate_dps"] for p in truth["plateaus"]])
    k = np.polyfit(w, np.array(truth["outputs"]), 1)[0]
    assert abs(ld["scale_factor"] - k) < 4 * ld["scale_factor_sigma"]
    assert main([*args, "--rate-tolerance", "-1"]) == 2
    _one_line_error(capsys, "--rate-tolerance")


@pytest.fixture(scope="module")
def program(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    """``simulate ratetable --no-rate-column``: a program's record, its start unknown."""
    d = tmp_path_factory.mktemp("rt3")
    assert main(["simulate", "ratetable", "--no-rate-column", "--rate-hz", "50", "-o",
                 str(d / "prog.csv"), "--truth", str(d / "truth.json")]) == 0  # fmt: skip
    (truth,) = json.loads((d / "truth.json").read_text())["files"]
    return d / "prog.csv", truth


def test_rates_with_a_dwell_place_the_plateaus(
    program: tuple[Path, dict], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path, truth = program
    assert "table_rate" not in path.read_text().splitlines()[0]
    assert truth["lead_s"] > 5.0 and truth["dwell_s"] == 20.0
    before = _sha(path)
    rates = ",".join(f"{r:g}" for r in truth["order_dps"])
    assert main(["ratetable", str(path), f"--rates={rates}", "--dwell", "20s", "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    (det,) = res["plateaus"]
    assert det["source"] == "dwell" and det["found"] == ["start", "accel"]
    assert det["ladder_start_s"] == pytest.approx(truth["plateaus"][0]["start_s"], abs=0.03)
    assert det["accel_dps2"] == pytest.approx(truth["accel_dps2"], rel=2e-3)
    assert len(det["plateaus"]) == len(truth["plateaus"])  # no plateau cut short in a program
    for p, w in zip(det["plateaus"], truth["plateaus"], strict=True):
        assert p["rate_dps"] == w["rate_dps"]
        assert p["start_s"] == pytest.approx(w["start_s"] + 1.0, abs=0.03)
        assert p["end_s"] == pytest.approx(w["end_s"], abs=0.03)
    # the scale factor against numpy.polyfit on the truth's noise-free plateau outputs
    k_true = np.polyfit([p["rate_dps"] for p in truth["plateaus"]], truth["outputs"], 1)[0]
    ld = res["ladders"][0]
    assert abs(ld["scale_factor"] - k_true) < 5 * ld["scale_factor_sigma"]
    # the same program as a schedule file of rate_dps,dwell_s rows
    sched = tmp_path / "program.csv"
    sched.write_text("rate_dps,dwell_s\n" + "".join(f"{r:g},20\n" for r in truth["order_dps"]))
    assert main(["ratetable", str(path), "--schedule", str(sched), "--json"]) == 0
    res2 = json.loads(capsys.readouterr().out)
    assert res2["plateaus"][0]["ladder_start_s"] == det["ladder_start_s"]
    assert res2["ladders"][0]["scale_factor"] == ld["scale_factor"]
    assert main(["ratetable", str(path), f"--rates={rates}", "--dwell", "20s"]) == 0
    out = capsys.readouterr().out
    assert "plateaus from the rates and their dwell" in out and "(found)" in out
    assert _sha(path) == before


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        (["--dwell", "21s"], ("beyond the record", "--dwell")),
        (["--dwell", "1min"], ("beyond the record", "--dwell")),
        (["--dwell", "20", "--start", "2000"], ("beyond the record", "--start")),
        (["--dwell", "twenty"], ("--dwell", "twenty")),
        (["--dwell", "20,20"], ("--dwell", "one a rate")),
        (["--dwell", "20", "--rate-column", "table_rate"], ("--dwell", "--rate-column")),
    ],
)
def test_dwell_that_does_not_fit_refused(
    program: tuple[Path, dict],
    capsys: pytest.CaptureFixture[str],
    extra: list[str],
    words: tuple[str, ...],
) -> None:
    path, truth = program
    rates = ",".join(f"{r:g}" for r in truth["order_dps"])
    assert main(["ratetable", str(path), f"--rates={rates}", *extra]) == 2
    _one_line_error(capsys, *words)


def test_start_without_a_dwell_refused(
    program: tuple[Path, dict], capsys: pytest.CaptureFixture[str]
) -> None:
    path, truth = program
    rates = ",".join(f"{r:g}" for r in truth["order_dps"])
    assert main(["ratetable", str(path), f"--rates={rates}", "--start", "3"]) == 2
    _one_line_error(capsys, "--start", "--dwell")
    assert main(["ratetable", str(path), "--dwell", "20"]) == 2
    _one_line_error(capsys, "--dwell", "--rates")


def test_a_ladder_from_a_bag_topic_and_its_stamps(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A ladder logged in a ROS bag beside a second IMU: --topic picks the table's IMU (rad/s,
    so the scale factor is dimensionless); --stamp receive reads the recorder's clock, here
    running at half the header stamps' pace: the plateaus' times double."""
    rec, truth = simulate_ladder(np.random.default_rng(11), rates_dps=LADDER, dwell_s=10.0,
                                 rate_hz=50.0)  # fmt: skip
    n = rec.n_samples
    header = (1_700_000_000 * NS + np.round(rec.time_s * NS)).astype(np.int64)
    receive = header[0] + 2 * (header - header[0])
    imu = np.zeros((n, 6))
    imu[:, 2] = np.deg2rad(rec.columns["gyro"])  # the table's axis: z, in rad/s
    imu[:, 5] = 9.80665
    bag = write_bag(tmp_path / "ladder.bag", "ros1", [
        Topic("/imu_table", "sensor_msgs/msg/Imu", header, receive, imu),
        Topic("/imu_room", "sensor_msgs/msg/Imu", header, receive, np.zeros((n, 6))),
    ])  # fmt: skip
    rates = ",".join(f"{r:g}" for r in LADDER)
    base = ["ratetable", str(bag), "--gyro", "gyro_z", f"--rates={rates}", "--json"]
    got = {}
    for stamp in ("header", "receive"):
        assert main([*base, "--topic", "/imu_table", "--stamp", stamp]) == 0
        got[stamp] = json.loads(capsys.readouterr().out)
    k = np.polyfit(np.array(LADDER), np.array(truth["outputs"]), 1)[0]
    for res in got.values():
        ld = res["ladders"][0]
        assert res["scale_factor_unit"] == "1"
        assert abs(ld["scale_factor"] - k) < 4 * ld["scale_factor_sigma"]
    ends = [[p["end_s"] for p in got[s]["plateaus"][0]["plateaus"]] for s in got]
    assert np.allclose(ends[1], 2.0 * np.array(ends[0]), atol=1.0), ends
    assert main(base) == 2  # two Imu topics, none named
    _one_line_error(capsys, "--topic")


def test_a_gyro_unit_against_the_file_is_said_as_typed(
    ladder_csv: tuple[Path, dict], capsys: pytest.CaptureFixture[str]
) -> None:
    path, _ = ladder_csv  # the file says deg/s
    rates = ",".join(f"{r:g}" for r in LADDER)
    assert main(["ratetable", str(path), f"--rates={rates}", "--gyro-unit", "counts"]) == 0
    err = capsys.readouterr().err
    assert "--gyro-unit counts contradicts the file's metadata" in err, err
    assert "--signal-unit" not in err
