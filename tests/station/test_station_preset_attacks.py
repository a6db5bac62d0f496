"""Hostile controller presets and register encodings (:mod:`thermocal.station.config`,
:mod:`thermocal.station.chamber`): wrong types and conflicts, a scale that cannot hold the
program, and 16-bit encodings that refuse instead of wrapping (boundaries written out
here)."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

import pytest

from station_toml import sensor_toml
from thermocal.cli import main


def _run(argv: list[str]) -> tuple[int, str, str]:
    o, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(o), contextlib.redirect_stderr(e):
        code = main(argv)
    return code, o.getvalue(), e.getvalue()


def _refused(argv: list[str], *words: str) -> str:
    """Exit 2, exactly one ``error:`` line holding every word, no traceback."""
    code, _o, err = _run(argv)
    errors = [ln for ln in err.splitlines() if ln.startswith("error:")]
    assert code == 2, (code, err)
    assert len(errors) == 1 and "Traceback" not in err, err
    for w in words:
        assert w in errors[0], (w, errors[0])
    return errors[0]


STATION_SENSOR = sensor_toml("/dev/null", stale_s=None)


def _station_toml(tmp: Path, chamber: str) -> Path:
    """A station whose chamber is a Modbus TCP controller at port 1 of this machine (nothing
    listens there: a run that got as far as the chamber would fail to connect)."""
    p = tmp / "STATION.toml"
    head = '[chamber]\ndriver = "modbus-tcp"\nhost = "127.0.0.1"\nport = 1\nio_timeout_s = 0.2\n'
    p.write_text(head + chamber + "\n" + STATION_SENSOR, encoding="utf-8")
    return p


def _program(tmp: Path) -> Path:
    p = tmp / "prog.csv"
    p.write_text("time_s,setpoint_c\n0,25\n600,60\n1200,-20\n", encoding="utf-8")
    return p


@pytest.mark.parametrize(
    ("chamber", "words"),
    [
        ("preset = 5\nscale = 0.1", ("preset must be str",)),
        ('preset = ["eurotherm-2000"]\nscale = 0.1', ("preset must be str",)),
        ('preset = ""\nscale = 0.1', ("unknown preset ''", "eurotherm-2000")),
        ('preset = "eurotherm-2000"', ("needs scale",)),
        ('preset = "eurotherm-2000"\nscale = "0.1"', ("scale must be float",)),
        ('preset = "eurotherm-2000"\nscale = 0', ("scale must be > 0",)),
        ('preset = "eurotherm-2000"\nscale = -0.1', ("scale must be > 0",)),
        ('preset = "eurotherm-2000"\nscale = nan', ("scale must be finite",)),
        ('preset = "eurotherm-2000"\nscale = 0.1\nsetpoint_register = 2', ("disagrees",)),
        ('preset = "eurotherm-2000"\nscale = 0.1\nsigned = false', ("disagrees",)),
        ('preset = "eurotherm-2000"\nscale = 0.1\nregister_kind = "input"', ("disagrees",)),
    ],
)
def test_preset_wrong_types_and_conflicts(
    tmp_path: Path, chamber: str, words: tuple[str, ...]
) -> None:
    toml = _station_toml(tmp_path, chamber)
    argv = ["station", "run", str(toml), "--profile", str(_program(tmp_path))]
    _refused([*argv, "-o", str(tmp_path / "out")], "[chamber]", *words)
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    ("scale", "words"),
    [
        ("5e-324", ("does not fit a signed 16-bit register",)),  # was OverflowError, exit 1
        ("0.001", ("set-point 60 °C does not fit",)),  # ±32.767 °C: 60 and −20 do not fit
        ("100", ("would be written as 0 °C",)),  # 25 °C rounds to 0 counts: 0 °C written
        ("1e300", ("would be written as 0 °C",)),
    ],
)
def test_preset_scale_that_cannot_hold_the_program(
    tmp_path: Path, scale: str, words: tuple[str, ...]
) -> None:
    """Every set-point of the program (and the safe one) is checked before anything is
    written or the chamber is contacted.  Seen red before the fix: scale 5e-324 raised
    OverflowError (exit 1); scales 100 and 1e300 passed the check (25 °C → 0 counts, 60 °C
    → 1 count = 100 °C) and the run went on to the chamber, creating the folder."""
    toml = _station_toml(tmp_path, f'preset = "eurotherm-2000"\nscale = {scale}')
    argv = ["station", "run", str(toml), "--profile", str(_program(tmp_path))]
    _refused([*argv, "-o", str(tmp_path / "out")], *words)
    assert not (tmp_path / "out").exists()


def test_register_encoding_refuses_instead_of_wrapping() -> None:
    """The 16-bit boundaries written out: signed at 0.1 °C/count holds −3276.8…3276.7 °C
    (−3276.8 is 0x8000), unsigned 0…6553.5 °C; one count beyond is refused, not wrapped; a
    set-point that is not a number is refused (seen red: ValueError/OverflowError)."""
    from thermocal.errors import ThermocalInputError
    from thermocal.station.chamber import RegisterMap

    signed = RegisterMap(24, 1, "holding", 0.1, True)
    unsigned = RegisterMap(24, 1, "holding", 0.1, False)
    assert signed.encode(3276.7) == 32767
    assert signed.encode(-3276.8) == 0x8000
    assert signed.decode(0x8000) == pytest.approx(-3276.8)
    assert unsigned.encode(6553.5) == 65535
    for m, v in ((signed, 3276.8), (signed, -3276.9), (unsigned, -0.1), (unsigned, 6553.6)):
        with pytest.raises(ThermocalInputError, match="does not fit"):
            m.encode(v)
    for v in (float("nan"), float("inf"), -float("inf")):
        with pytest.raises(ThermocalInputError, match="does not fit"):
            signed.encode(v)
