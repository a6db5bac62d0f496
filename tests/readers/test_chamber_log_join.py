"""A chamber log joined to a recording through read_recording (ReadOptions.chamber_log): the
column ``chamber`` at the recording's samples, the join recorded in its metadata."""

from __future__ import annotations

import datetime as dt
import warnings
from pathlib import Path

import numpy as np
import pytest

from chamber_logs import KNOTS_C, KNOTS_S, write_log, write_recording
from thermocal.errors import ThermocalInputError, TimestampWarning
from thermocal.readers import ReadOptions, read_recording
from thermocal.readers.options import ChamberLogSpec

MAX_RATE_C_PER_S = float(np.max(np.abs(np.diff(KNOTS_C) / np.diff(KNOTS_S))))
"""The air's steepest ramp [°C/s]: one recording sample (1 s) of time error shows as this."""


def _read(rec: Path, spec: ChamberLogSpec, temps: str = "T,chamber") -> object:
    return read_recording(
        rec,
        ReadOptions(signals="gx", temperatures=temps, time_unit="s", signal_unit="deg/h",
                    temp_unit="degC", chamber_log=spec),
    )  # fmt: skip


def test_hhmm_fahrenheit_log_20_s_off_joined_within_one_sample(tmp_path: Path) -> None:
    log = write_log(tmp_path / "log.csv", style="hh:mm", unit="degF")
    rec_path, truth = write_recording(tmp_path / "rec.csv", offset_s=20.0)
    with pytest.warns(TimestampWarning, match=r"offset 20\.\d* ± 0\.\d+ s, drift"):
        rec = _read(rec_path, ChamberLogSpec(str(log)))
    stated = rec.meta.extra["chamber_log"]  # type: ignore[attr-defined]
    assert stated["method"] == "correlation" and stated["unit"] == "degF"
    assert abs(stated["offset_s"] - 20.0) < 1.0  # within one recording sample
    assert rec.temperatures == ("T", "chamber")  # type: ignore[attr-defined]
    joined = rec.temperature_c("chamber")  # type: ignore[attr-defined]
    assert float(np.max(np.abs(joined - truth))) < MAX_RATE_C_PER_S * 1.0
    assert rec.units["chamber"] == "degC"  # type: ignore[attr-defined]


@pytest.mark.parametrize("unit", ["K", "degC"])
def test_kelvin_and_celsius_logs_with_a_given_offset(tmp_path: Path, unit: str) -> None:
    log = write_log(tmp_path / "log.csv", style="hh:mm:ss", period_s=10.0, unit=unit, decimals=3)
    rec_path, truth = write_recording(tmp_path / "rec.csv", offset_s=1234.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a given offset: nothing doubtful to say
        rec = _read(rec_path, ChamberLogSpec(str(log), offset_s=1234.0), temps="chamber")
    assert rec.temperatures == ("chamber",)  # type: ignore[attr-defined]
    np.testing.assert_allclose(rec.temperature_c("chamber"), truth, atol=1e-3)  # type: ignore[attr-defined]
    stated = rec.meta.extra["chamber_log"]  # type: ignore[attr-defined]
    assert (stated["method"], stated["offset_sigma_s"], stated["unit"]) == ("given", None, unit)


def test_absolute_times_and_the_log_zone(tmp_path: Path) -> None:
    local = dt.datetime(2026, 3, 14, 23, 30, 0)  # the log passes midnight, its date above it
    log = write_log(tmp_path / "log.csv", start=local, style="12h", date="header")
    utc_start = local.replace(tzinfo=dt.UTC).timestamp() - 2 * 3600.0  # UTC+02:00
    rec_path, truth = write_recording(tmp_path / "rec.csv", offset_s=20.0, t0=utc_start + 20.0)
    with pytest.raises(ThermocalInputError, match="give chamber_tz"):
        _read(rec_path, ChamberLogSpec(str(log)))
    rec = _read(rec_path, ChamberLogSpec(str(log), tz="+02:00"))
    stated = rec.meta.extra["chamber_log"]  # type: ignore[attr-defined]
    assert (stated["method"], stated["timezone"]) == ("absolute", "UTC+02:00")
    assert stated["offset_s"] == pytest.approx(20.0, abs=1e-3)
    assert float(np.max(np.abs(rec.temperature_c("chamber") - truth))) < 0.01  # type: ignore[attr-defined]
    with pytest.raises(ThermocalInputError, match="does not overlap the recording"):
        _read(rec_path, ChamberLogSpec(str(log), tz="-08:00"))


def test_a_log_that_does_not_overlap_is_refused(tmp_path: Path) -> None:
    log = write_log(tmp_path / "log.csv", span_s=6000.0)
    rec_path, _ = write_recording(tmp_path / "rec.csv", offset_s=20.0, span_s=3000.0)
    with pytest.raises(ThermocalInputError, match=r"log\.csv: the chamber log does not overlap"):
        _read(rec_path, ChamberLogSpec(str(log), offset_s=9000.0))
