"""The crash-safe recording folder of a station run.

Layout of ``DIR``::

    station.json              config, profile, start time, runs, parts, events
    imu1-0000.parquet         closed parts of sensor ``imu1`` (every ``part_s`` seconds)
    chamber-0000.parquet      the chamber's polled temperature and set-point
    imu1.bad.txt              bad lines of ``imu1``: host time, line index, reason, text
    .imu1-0007.parquet.tmp    a part being written: no reader accepts the name

Rows wait in memory until their part is closed; the part is written under the temporary
name, flushed to disk (``fsync``) and renamed.  A SIGKILL therefore loses at most the rows
of the open part; every closed part is complete.  ``station.json`` is rewritten the same
way (temporary, ``fsync``, rename) after each part and event.  A part's Parquet key-value
metadata holds the thermocal metadata object (:func:`thermocal.readers.dispatch.recording_info`'s
layout: time column, units of every column, the sensor id and the station's metadata), so
each part is a complete recording on its own and
:func:`thermocal.readers.station.read_station` concatenates them.

Columns of a sensor part: ``time`` [s since the recording's start; from the line's own
time field, else ``line index / rate_hz`` anchored at the run's first line, else the host
time], ``host_time`` [s since the start], the sensor's named fields in their units,
``chamber_c`` (the chamber's last polled temperature [°C], NaN when unknown), ``setpoint_c``
(the set-point last written [°C]) and ``program_s`` (the program's time [s]).
"""

from __future__ import annotations

import datetime as _dt
import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from thermocal import units
from thermocal.errors import ThermocalInputError
from thermocal.readers.station import (
    CHAMBER_STREAM,
    STATION_FORMAT,
    STATION_JSON,
    STATION_VERSION,
    closed_parts,
    is_station_path,
    read_station,
    read_station_json,
    station_files,
)
from thermocal.station import clock
from thermocal.station.config import StationConfig

STATION_COLUMNS = {
    "time": "s",
    "host_time": "s",
    "chamber_c": "degC",
    "setpoint_c": "degC",
    "program_s": "s",
}
"""The station's own columns and their units."""


RESUME_SENSOR_KEYS = ("names", "units", "delimiter", "decimal", "rate_hz")
"""The keys of a ``[[sensor]]`` that a resumed run must find unchanged."""
RESUME_CHAMBER_KEYS = ("setpoint_register", "temperature_register", "register_kind", "scale",
                       "signed")  # fmt: skip
"""The keys of ``[chamber]`` that a resumed run must find unchanged."""

BAD_TEXT_MAX = 200
"""Characters of a bad line kept in ``SENSOR.bad.txt`` (the rest counted)."""

LOCK_NAME = ".station.lock"
"""The lock file of a recording folder (its one writer's process id)."""


def _fsync_write(path: Path, data: bytes) -> None:
    tmp = path.with_name("." + path.name + ".tmp")
    with open(tmp, "wb") as fh:
        fh.write(data)
        fh.flush()
        os.fsync(fh.fileno())
    os.replace(tmp, path)


def part_name(stream: str, index: int) -> str:
    """The file name of part ``index`` of ``stream`` (``chamber-0001.parquet``).

    Parameters
    ----------
    stream : str
        The stream (``chamber`` or a sensor id).
    index : int
        The part's number.

    Returns
    -------
    str
    """
    return f"{stream}-{index:04d}.parquet"


def _column_units(names: tuple[str, ...], units_: tuple[str, ...]) -> dict[str, str]:
    return dict(zip(names, units_, strict=True))


def _is_temperature(unit: str) -> bool:
    try:
        return units.normalize_temperature_unit(unit) == "degC"
    except ThermocalInputError:
        return False


@dataclass
class _Stream:
    """One stream's rows waiting for their part."""

    name: str
    columns: list[str]
    units: dict[str, str]
    next_index: int = 0
    rows: int = 0

    def __post_init__(self) -> None:
        self.data: dict[str, list[float]] = {c: [] for c in self.columns}


class Recorder:
    """Writes the parts and ``station.json`` of one recording folder.

    ``start_unix`` is the recording's start (host wall clock [s]); a resumed recording keeps
    the first run's.  Not thread-safe: the station's loop calls it.
    """

    def __init__(
        self,
        out_dir: Path,
        cfg: StationConfig,
        program: tuple[list[float], list[float]],
        *,
        profile_source: str,
        time_scale: float,
        resume: bool,
    ) -> None:
        self.dir = out_dir
        self.cfg = cfg
        self.resume = resume
        self.time_scale = time_scale
        self.streams: dict[str, _Stream] = {}
        self.removed_tmp: list[str] = []
        self._lock_fd: int | None = None
        self.created = False
        self.write_error = ""
        try:
            self._open(out_dir, cfg, program, profile_source, time_scale)
        except BaseException:
            self.release()
            raise

    def _open(
        self,
        out_dir: Path,
        cfg: StationConfig,
        program: tuple[list[float], list[float]],
        profile_source: str,
        time_scale: float,
    ) -> None:
        """Lock and load (``resume``) or create the folder; declare the streams; record
        the run."""
        resume = self.resume
        if resume:
            if out_dir.is_dir():
                self._lock()
            self.doc = self._load_for_resume(program)
        else:
            if out_dir.exists() and (not out_dir.is_dir() or any(out_dir.iterdir())):
                raise ThermocalInputError.naming(
                    f"{out_dir}: exists and is not empty; continue it with {{resume}} or name "
                    "another -o",
                    "resume",
                )
            self.created = not out_dir.exists()
            try:
                out_dir.mkdir(parents=True, exist_ok=True)
                self._lock()
            except OSError as exc:  # a read-only place, a file in the way, no such mount
                raise ThermocalInputError(
                    f"{out_dir}: cannot create the recording folder "
                    f"({exc.strerror or type(exc).__name__}); give another -o"
                ) from None
            if (out_dir / STATION_JSON).exists():  # another run started in between
                self.release()
                raise ThermocalInputError(f"{out_dir}: another station run started in it")
            now = clock.now()
            self.doc = {
                "format": STATION_FORMAT,
                "version": STATION_VERSION,
                "config": cfg.to_dict(),
                "profile": {
                    "source": profile_source,
                    "time_s": list(program[0]),
                    "setpoint_c": list(program[1]),
                },
                "start_unix": now,
                "start_utc": _dt.datetime.fromtimestamp(now, _dt.UTC).isoformat(),
                "time_scale": time_scale,
                "runs": [],
                "parts": [],
                "events": [],
            }
        self.start_unix = float(self.doc["start_unix"])
        self._declare_streams()
        self.part_started = clock.now()
        self.doc["runs"].append(
            {"start_unix": clock.now(), "time_scale": time_scale, "resumed": resume}
        )
        self.save()

    # --- the folder's one writer ----------------------------------------------------------
    def _lock(self) -> None:
        """Hold ``DIR/.station.lock`` (an advisory ``flock``, released by the system when the
        process ends, even by SIGKILL): a second run on the folder is refused."""
        try:
            import fcntl
        except ImportError:  # no flock on this system: one writer is the operator's care
            return
        path = self.dir / LOCK_NAME
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            holder = os.read(fd, 32).decode("ascii", "replace").strip() or "?"
            os.close(fd)
            raise ThermocalInputError.naming(
                f"{self.dir}: another station run (process {holder}) is writing this folder; "
                "wait for it to end, or stop it, before {resume}",
                "resume",
            ) from None
        os.ftruncate(fd, 0)
        os.write(fd, str(os.getpid()).encode())
        self._lock_fd = fd

    def release(self) -> None:
        """Let another run write the folder."""
        if self._lock_fd is not None:
            os.close(self._lock_fd)
            self._lock_fd = None

    def discard(self) -> None:
        """A new recording whose run never started: remove what it wrote (``station.json``,
        the lock, the folder when this run created it), so the corrected command starts
        afresh.  A resumed recording is left as it is (``resume`` accepts it again)."""
        import contextlib

        if self.resume:
            self.release()
            return
        for name in (STATION_JSON, LOCK_NAME, "." + STATION_JSON + ".tmp"):
            with contextlib.suppress(FileNotFoundError):
                (self.dir / name).unlink()
        self.release()
        if self.created:
            with contextlib.suppress(OSError):
                self.dir.rmdir()

    # --- setup ------------------------------------------------------------------------
    def _load_for_resume(self, program: tuple[list[float], list[float]]) -> dict[str, Any]:
        doc = read_station_json(self.dir)
        rec = doc.get("profile") or {}
        if [float(x) for x in rec.get("time_s", [])] != [float(x) for x in program[0]] or [
            float(x) for x in rec.get("setpoint_c", [])
        ] != [float(x) for x in program[1]]:
            raise ThermocalInputError.naming(
                f"{self.dir}: {{resume}} with another program than the recording's "
                f"({rec.get('source', '?')}); give the same {{profile}}",
                "resume",
                "profile",
            )
        self._same_setup(doc.get("config"))
        for p in self.dir.glob(".*.parquet.tmp"):  # the part open at the crash
            self.removed_tmp.append(p.name)
            p.unlink()
        doc["parts"] = [  # what is on disk, whatever the last station.json said
            {"stream": s, "file": p.name} for s, _i, p in closed_parts(self.dir)
        ]
        return doc

    def _same_setup(self, old: Any) -> None:
        """``resume`` with the recording's sensors (ids, names, units, rate, separators)
        and chamber map (registers, scale, sign): the folder is read as one recording, in
        one set of units, so a difference is refused naming the key and both values."""
        new = self.cfg.to_dict()
        old = old if isinstance(old, dict) else {}
        where = f"{self.dir}: {{resume}} with another STATION.toml than the recording's"
        old_s = {s.get("id"): s for s in old.get("sensors", []) if isinstance(s, dict)}
        new_s = {s["id"]: s for s in new["sensors"]}
        if sorted(map(str, old_s)) != sorted(new_s):
            raise ThermocalInputError.naming(
                f"{where}: sensors {sorted(map(str, old_s))} recorded, {sorted(new_s)} given; "
                "give the same [[sensor]] ids",
                "resume",
            )
        pairs = [(f"sensor {sid!r} {k}", old_s[sid].get(k), new_s[sid][k]) for sid in new_s
                 for k in RESUME_SENSOR_KEYS]  # fmt: skip
        och = old.get("chamber") if isinstance(old.get("chamber"), dict) else {}
        pairs += [(f"[chamber] {k}", och.get(k), new["chamber"][k]) for k in RESUME_CHAMBER_KEYS]
        for key, was_, now_ in pairs:
            was, now = json.loads(json.dumps(was_)), json.loads(json.dumps(now_))
            if was != now:
                raise ThermocalInputError.naming(
                    f"{where}: {key} was {was!r}, now {now!r} (the folder would be read in "
                    f"the new setting); give the recording's value or record into another -o",
                    "resume",
                )

    def _declare_streams(self) -> None:
        existing = closed_parts(self.dir)
        nxt: dict[str, int] = {}
        for s, i, _p in existing:
            nxt[s] = max(nxt.get(s, 0), i + 1)
        for sc in self.cfg.sensors:
            own = [n for n in sc.names if n != sc.time_name]
            cols = ["time", "host_time", *own, "chamber_c", "setpoint_c", "program_s"]
            u = {**STATION_COLUMNS, **{n: x for n, x in _column_units(sc.names, sc.units).items()
                                       if n != sc.time_name}}  # fmt: skip
            self.streams[sc.id] = _Stream(sc.id, cols, u, nxt.get(sc.id, 0))
        cols = ["time", "program_s", "setpoint_c", "chamber_c"]
        self.streams[CHAMBER_STREAM] = _Stream(
            CHAMBER_STREAM, cols, {c: STATION_COLUMNS[c] for c in cols},
            nxt.get(CHAMBER_STREAM, 0),
        )  # fmt: skip

    # --- rows, parts, events ---------------------------------------------------------------
    def rel(self, unix: float) -> float:
        """Host wall-clock time → seconds since the recording's start.

        Parameters
        ----------
        unix : float
            Host time [s since 1970].

        Returns
        -------
        float
            Seconds since the start [s].
        """
        return unix - self.start_unix

    def add(self, stream: str, row: dict[str, float]) -> None:
        """Buffer one sample ``row`` of ``stream`` (written when its part closes).

        Parameters
        ----------
        stream : str
            The stream (``chamber`` or a sensor id).
        row : dict
            One sample's fields.
        """
        st = self.streams[stream]
        for c in st.columns:
            st.data[c].append(float(row.get(c, float("nan"))))
        st.rows += 1

    def _meta(self, st: _Stream) -> dict[str, Any]:
        from thermocal.recording import META_FORMAT, META_VERSION

        temps = {c: u for c, u in st.units.items() if c != "time" and _is_temperature(u)}
        sigs = {}
        if st.name != CHAMBER_STREAM:
            sc = next(s for s in self.cfg.sensors if s.id == st.name)
            sigs = {
                n: u for n, u in zip(sc.names, sc.units, strict=True)
                if n != sc.time_name and not _is_temperature(u)
            }  # fmt: skip
            temps = {n: u for n, u in zip(sc.names, sc.units, strict=True) if _is_temperature(u)}
        others = {c: u for c, u in st.units.items() if c not in sigs and c not in temps}
        others.pop("time", None)
        station = {
            "start_unix": self.start_unix,
            "start_utc": self.doc["start_utc"],
            "time_scale": self.time_scale,
            "stream": st.name,
            "chamber": self.doc["config"]["chamber"]["driver"],
            "profile": self.doc["profile"]["source"],
        }
        return {
            "format": META_FORMAT,
            "version": META_VERSION,
            "time": "time",
            "time_unit": "s",
            "signals": sigs,
            "temperatures": temps,
            "units": others,
            "metadata": {"sensor_id": st.name, "extra": {"station": station}},
        }

    def close_parts(self) -> list[str]:
        """Close the open part of every stream that has rows; returns the files written."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        from thermocal.recording import META_KEY

        written = []
        for st in self.streams.values():
            if st.rows == 0:
                continue
            table = pa.table({c: pa.array(st.data[c], pa.float64()) for c in st.columns})
            table = table.replace_schema_metadata({META_KEY: json.dumps(self._meta(st))})
            name = part_name(st.name, st.next_index)
            final = self.dir / name
            tmp = self.dir / ("." + name + ".tmp")
            try:
                pq.write_table(table, tmp, write_page_checksum=True)
                with open(tmp, "rb") as fh:
                    os.fsync(fh.fileno())
                os.replace(tmp, final)
            except OSError as exc:
                self._failed(tmp, exc)
                continue  # already failing: the rows stay in memory, the stop goes on
            self.doc["parts"].append(
                {
                    "stream": st.name,
                    "file": name,
                    "rows": st.rows,
                    "time_first": st.data["time"][0],
                    "time_last": st.data["time"][-1],
                    "program_s_last": st.data["program_s"][-1],
                }
            )
            written.append(name)
            st.next_index += 1
            st.rows = 0
            st.data = {c: [] for c in st.columns}
        self.part_started = clock.now()
        if written:
            self.save()
        return written

    def maybe_rotate(self, now_unix: float) -> list[str]:
        """Close the open parts when they are ``part_s`` old at host time ``now_unix`` [s];
        return the names closed.

        Parameters
        ----------
        now_unix : float
            Host time now [s since 1970].

        Returns
        -------
        list of str
        """
        if now_unix - self.part_started >= self.cfg.part_s:
            return self.close_parts()
        return []

    def event(self, kind: str, message: str, **fields: Any) -> None:
        """Record an event (``kind``, ``message`` and its fields) in ``station.json``.

        Parameters
        ----------
        kind : str
            The event's kind.
        message : str
            The text.
        **fields
            The event's other fields.
        """
        now = clock.now()
        self.doc["events"].append(
            {"time": self.rel(now), "kind": kind, "message": message, **fields}
        )
        self.save()

    def bad_lines(self, sensor: str, rows: list[tuple[float, int, str, str]]) -> None:
        """Append bad lines to ``DIR/<sensor>.bad.txt`` (flushed at once).

        Parameters
        ----------
        sensor : str
            The sensor's id.
        rows : list of (float, int, str, str)
            Host time [s], line number, the line and why it is bad.
        """
        if not rows:
            return
        path = self.dir / f"{sensor}.bad.txt"
        try:
            with open(path, "a", encoding="utf-8") as fh:
                for t, idx, reason, text in rows:
                    if len(text) > BAD_TEXT_MAX:  # a 10 MB line is not kept whole
                        text = text[:BAD_TEXT_MAX] + f"… ({len(text):,} characters)"
                    fh.write(f"{self.rel(t):.6f}\t{idx}\t{reason}\t{text}\n")
                fh.flush()
                os.fsync(fh.fileno())
        except OSError as exc:
            self._failed(path, exc)

    def save(self) -> None:
        """Write ``station.json`` atomically."""
        path = self.dir / STATION_JSON
        try:
            _fsync_write(path, json.dumps(self.doc, indent=1).encode())
        except OSError as exc:
            self._failed(path, exc)

    def _failed(self, path: Path, exc: OSError) -> None:
        """A write that failed (a full disk, a file-size limit, a folder gone): the first
        raises :class:`ThermocalInputError` naming the file, so the run stops safely; later
        ones, during that safe stop, are ignored (the first error is the one reported)."""
        if self.write_error:
            return
        import re

        code = exc.errno or next(iter(re.findall(r"\[errno (\d+)\]", str(exc))), None)
        why = os.strerror(int(code)) if code else (str(exc)[:200] or type(exc).__name__)
        self.write_error = (
            f"{path}: cannot write ({why}): free space (or fix the folder) and continue "
            "with {resume}; the closed parts are kept"
        )
        raise ThermocalInputError.naming(self.write_error, "resume") from None


__all__ = [
    "STATION_FORMAT",
    "STATION_JSON",
    "STATION_VERSION",
    "Recorder",
    "closed_parts",
    "is_station_path",
    "read_station",
    "read_station_json",
    "station_files",
]
