"""Hostile ``export-params`` options and calibrations (issue 26 item 7), through the CLI.

A good calibration (a gyro and an accelerometer triad, cubic in one temperature) is fitted
once from a recording generated here; each attack runs ``export-params`` on it (or on a copy
edited in code, its checksums recomputed as anyone can) and must end in exit 2 with one
``error:`` line naming the option, channel or parameter, no output file, and every input
byte for byte unchanged.  The firmware limits the attacks probe are cited in
:data:`thermocal.firmware.formats.FORMATS` (PX4 ``TC_G0…3``/``TC_A0…3``, ArduPilot
``INS_TCAL1…3``) and :data:`thermocal.export.params.FLOAT32_MAX`.
"""

from __future__ import annotations

import contextlib
import copy
import hashlib
import io
import json
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from thermocal.cli import main
from thermocal.models.format import checksum
from thermocal.outputs import TEMP_SUFFIX

GYROS, ACCELS = ("gx", "gy", "gz"), ("ax", "ay", "az")


def _recording_csv() -> bytes:
    """400 s at 1 Hz, 10 → 40 °C; gyros in deg/s, accelerometers in mg (+z up)."""
    rng = np.random.default_rng(26)
    n = 400
    t = np.arange(n, dtype=float)
    temp = 10.0 + 30.0 * t / (n - 1)
    cols: dict[str, np.ndarray] = {"time": t, "T1": temp}
    for name, c in zip(GYROS, (0.1, 0.2, 0.3), strict=True):
        cols[name] = c + 0.01 * (temp - 25.0) + rng.normal(0.0, 0.001, n)
    for name, c in zip(ACCELS, (5.0, -3.0, 1000.0), strict=True):
        cols[name] = c + 0.3 * (temp - 25.0) + rng.normal(0.0, 0.5, n)
    lines = [",".join(cols)] + [
        ",".join(repr(float(v)) for v in row) for row in zip(*cols.values(), strict=True)
    ]
    return ("\n".join(lines) + "\n").encode()


@pytest.fixture(scope="module")
def good_calibration(tmp_path_factory: pytest.TempPathFactory) -> bytes:
    d = tmp_path_factory.mktemp("params-attack")
    (d / "d.csv").write_bytes(_recording_csv())
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        code = main(["fit", str(d / "d.csv"), "--model", "poly", "--order", "3", "--signal",
                     ",".join(GYROS + ACCELS), "--signal-unit", "deg/s,deg/s,deg/s,mg,mg,mg",
                     "--time-unit", "s", "--temps", "T1", "--temp-unit", "degC",
                     "--gravity-axis", "+z", "--gravity", "9.80665",
                     "-o", str(d / "cal.json")])  # fmt: skip
    assert code == 0
    return (d / "cal.json").read_bytes()


def _edit_coef(index: int, value: float, channel: str = "gx") -> Callable[[dict[str, Any]], None]:
    """Set one of a channel's normalised polynomial coefficients, checksums recomputed.
    (NaN and infinity cannot be written: the checksum's canonical JSON refuses them, so
    they reach the parameters only through ``--tref``.)"""

    def edit(cal: dict[str, Any]) -> None:
        for ch in cal["channels"]:
            if ch["name"] == channel:
                ch["model"]["state"]["coef"][index] = value
                ch["model"].pop("checksum")
                ch["model"]["checksum"] = checksum(ch["model"])
        cal.pop("checksum")
        cal["checksum"] = checksum(cal)

    return edit


@dataclass(frozen=True)
class Attack:
    id: str
    argv: list[str]
    words: str
    """Expected in the ``error:`` line."""
    edit: Callable[[dict[str, Any]], None] | None = None


def _attacks() -> list[Attack]:
    px4 = ["--format", "px4", "--device-id", "1"]
    ardu = ["--format", "ardupilot"]
    out: list[Attack] = []
    # duplicated, mixed and foreign axes
    for kind, chans in (("gyro", GYROS), ("accel", ACCELS)):
        a, b, c = chans
        for trio in ((a, a, a), (a, b, a), (a, b, b), (c, b, c)):
            val = ",".join(trio)
            out.append(Attack(f"axes/{kind}-{val}", [*px4, f"--{kind}", val],
                              f"--{kind} {val}: channel"))  # fmt: skip
    out.append(Attack("axes/gyro-is-accel", [*px4, "--gyro", "ax,ay,az"], "not a gyro"))
    out.append(Attack("axes/accel-is-gyro", [*ardu, "--accel", "gx,gy,gz"], "not an accel"))
    out.append(Attack("axes/accel-mixed", [*px4, "--accel", "ax,ay,gz"], "'gz' is a gyro"))
    # instances the firmware does not have
    for fmt, args, bad in (
        ("px4", px4, ("4", "5", "-1", "99999999999999999999")),
        ("ardupilot", ardu, ("3", "7", "-1", "99999999999999999999")),
    ):
        for n in bad:  # fmt: skip
            out.append(Attack(f"instance/{fmt}-{n}", [*args, "--instance", n], f"--instance {n}"))
    # values that are not finite float32
    for fmt, args in (("px4", px4), ("ardupilot", ardu)):
        for v in ("nan", "inf", "-inf"):
            out.append(Attack(f"float32/{fmt}-tref-{v}", [*args, "--tref", v], "--tref"))
        for idx, v in ((2, 1e300), (0, 1e60), (1, -1e300)):
            out.append(Attack(f"float32/{fmt}-coef{idx}-{v!r}", args, "not a finite float32",
                              _edit_coef(idx, v)))  # fmt: skip
    out.append(Attack("float32/px4-tref-1e39", [*px4, "--tref", "1e39"],
                      "TC_G0_TREF = 1e+39: not a finite float32"))  # fmt: skip
    for v in ("2147483648", "99999999999999999999999", "-2147483649"):
        out.append(Attack(f"int32/px4-device-id-{v}", ["--format", "px4", "--device-id", v],
                          "TC_G0_ID"))  # fmt: skip
    return out


ATTACKS = _attacks()


def _digest(p: Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest()


def test_the_table_covers_item_7() -> None:
    classes = {a.id.split("/")[0] for a in ATTACKS}
    assert classes == {"axes", "instance", "float32", "int32"}
    assert len({a.id for a in ATTACKS}) == len(ATTACKS) >= 35


@pytest.mark.parametrize("attack", ATTACKS, ids=[a.id for a in ATTACKS])
def test_attack(
    attack: Attack, tmp_path: Path, good_calibration: bytes, capsys: pytest.CaptureFixture[str]
) -> None:
    cal_path = tmp_path / "cal.json"
    if attack.edit is None:
        cal_path.write_bytes(good_calibration)
    else:
        cal = copy.deepcopy(json.loads(good_calibration))
        attack.edit(cal)
        cal_path.write_text(json.dumps(cal))
    before = {p: _digest(p) for p in tmp_path.iterdir()}
    out = tmp_path / "out.params"
    code = main(["export-params", str(cal_path), "-o", str(out), *attack.argv])
    _o, err = capsys.readouterr()
    assert "Traceback" not in err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert code == 2, f"exit {code}; stderr: {err}"
    assert lines and lines[-1].startswith("error: "), err
    assert sum(ln.startswith("error: ") for ln in lines) == 1, err
    assert attack.words in lines[-1], lines[-1]
    assert "internal" not in lines[-1]
    assert not out.exists()
    assert not list(tmp_path.glob(f"**/*{TEMP_SUFFIX}"))
    assert {p: _digest(p) for p in before} == before, "an input file changed"


@pytest.mark.parametrize(("fmt", "instance"), [("px4", "3"), ("ardupilot", "2")])
def test_the_last_instance_the_firmware_has_is_written(
    tmp_path: Path, good_calibration: bytes, fmt: str, instance: str
) -> None:
    """The bounds are the firmware's, not one less: PX4 TC_G3/TC_A3, ArduPilot INS_TCAL3."""
    cal = tmp_path / "cal.json"
    cal.write_bytes(good_calibration)
    out = tmp_path / "out.params"
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        assert main(["export-params", str(cal), "--format", fmt, "--device-id", "1",
                     "--instance", instance, "-o", str(out)]) == 0  # fmt: skip
    text = out.read_text()
    assert (
        ("TC_G3_X0_0" in text and "TC_A3_X1_2" in text)
        if fmt == "px4"
        else ("INS_TCAL3_GYR1_X" in text and "INS_TCAL3_ACC3_Z" in text)
    )
    assert "nan" not in text and "inf" not in text
