"""Writing files without damaging anything: a temporary in the target's directory renamed
over the target when complete, staging directories for multi-file outputs, JSON and recordings."""

from __future__ import annotations

import contextlib
import errno
import fcntl
import glob
import hashlib
import json
import os
import secrets
import shutil
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from thermocal._lazy import LazyModule
from thermocal.defaults import PROGRAM_SETPOINT, PROGRAM_TIME
from thermocal.errors import (
    FileFormatError,
    ThermocalInputError,
)
from thermocal.outputs import (
    TEMP_SUFFIX,
    check_outputs,
    refuse_special,
    sidecar_path,
    warn_formula_names,
)
from thermocal.readers.dispatch import recording_info
from thermocal.readers.formats import file_kind, format_named
from thermocal.recording import META_KEY, FloatArray, Recording

if TYPE_CHECKING:
    import pandas as pd
    import pyarrow as pa
    import pyarrow.csv as pacsv
    import pyarrow.parquet as pq
else:
    pd = LazyModule("pandas")
    pa = LazyModule("pyarrow")
    pacsv = LazyModule("pyarrow.csv")
    pq = LazyModule("pyarrow.parquet")


def _default_mode() -> int:
    """Permissions of a newly created file under the current umask (``0o666 & ~umask``);
    ``mkstemp`` would otherwise leave outputs readable by their owner only."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def _writable_target(path: str | Path) -> Path:
    """``path`` as a Path, its directory created; an existing directory there is an
    input error (not an ``IsADirectoryError`` naming the temporary file)."""
    target = Path(path)
    refuse_special(target)  # a FIFO, a device, /proc…: never replaced by a regular file
    if target.is_dir():
        raise ThermocalInputError(f"{path}: is a directory, expected a file name")
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
    except (FileExistsError, NotADirectoryError):
        raise ThermocalInputError(
            f"{path}: cannot create the output, {target.parent} is not a directory"
        ) from None
    return target


_WRITE_ERRORS = frozenset(
    {errno.EACCES, errno.EPERM, errno.EROFS, errno.ENOSPC, errno.EDQUOT, errno.ENOENT, errno.EFBIG}
)
"""Errors of the user's environment while writing an output (permissions, a full disk)."""

WRITTEN: list[Path] = []
"""Outputs completed by this process, in order (the CLI names them when interrupted)."""


def _temp_path(target: Path) -> Path:
    """``.NAME.<pid>.<random>.thermocal-partial`` beside ``target``."""
    return target.with_name(f".{target.name}.{os.getpid()}.{secrets.token_hex(4)}{TEMP_SUFFIX}")


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # exists, owned by someone else
        return True
    return True


def remove_stale_temporaries(target: str | Path) -> list[Path]:
    """Remove the temporaries of ``target`` left by writers that no longer run.

    A temporary is ``.NAME.<pid>.<random>.thermocal-partial`` (:data:`TEMP_SUFFIX`);
    it is stale when no process ``pid`` exists (a writer killed by SIGKILL or a power
    cut).  Temporaries of live writers are left alone.

    Parameters
    ----------
    target : str or Path
        The output whose stale temporaries are removed.

    Returns
    -------
    list of Path
        The removed temporaries.
    """
    t = Path(target)
    removed: list[Path] = []
    pattern = f".{glob.escape(t.name)}.*{TEMP_SUFFIX}"
    for cand in t.parent.glob(pattern):
        middle = cand.name[len(t.name) + 2 : -len(TEMP_SUFFIX)]
        pid_text = middle.split(".", 1)[0]
        if not pid_text.isdigit() or _pid_alive(int(pid_text)):
            continue
        with contextlib.suppress(OSError):
            cand.unlink()
            removed.append(cand)
    return removed


@contextlib.contextmanager
def _output_lock(target: Path) -> Iterator[None]:
    """Serialise writers of one output: an exclusive ``flock`` on a lock file kept in the
    system's temporary directory (so the output's directory holds only the results),
    named by a hash of the output's absolute path.  A second writer waits its turn."""
    key = hashlib.sha256(str(target.resolve()).encode("utf-8")).hexdigest()[:32]
    lock_dir = Path(tempfile.gettempdir()) / f"thermocal-locks-{os.getuid()}"
    try:
        lock_dir.mkdir(mode=0o700, exist_ok=True)
        fd = os.open(lock_dir / f"{key}.lock", os.O_RDWR | os.O_CREAT, 0o600)
    except OSError:  # no usable temporary directory: write unserialised
        yield
        return
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)  # closing releases the lock


@contextlib.contextmanager
def _temporary_for(path: str | Path) -> Iterator[tuple[Path, Path]]:
    """(target, temporary) under the output lock, stale temporaries removed first; the
    temporary is renamed over the target when the block ends without an exception and
    removed otherwise."""
    target = _writable_target(path)
    with _output_lock(target):
        remove_stale_temporaries(target)
        tmp = _temp_path(target)
        try:
            yield target, tmp
            os.chmod(tmp, _default_mode())
            os.replace(tmp, target)
        except BaseException as exc:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
            if isinstance(exc, OSError) and exc.errno in _WRITE_ERRORS:
                # name the output the user asked for, not our temporary
                raise ThermocalInputError(
                    f"{target}: cannot write the output ({exc.strerror}); nothing was written"
                ) from None
            raise
    WRITTEN.append(target)


@contextlib.contextmanager
def atomic_write(path: str | Path, mode: str = "wb") -> Iterator[Any]:
    """Open a temporary file beside ``path``; rename it over ``path`` on success.

    On any exception the temporary file is removed and ``path`` is untouched.
    Writers of the same output are serialised; temporaries carry :data:`TEMP_SUFFIX`.

    Parameters
    ----------
    path : str or Path
        The output file.
    mode : str, optional
        Mode of :func:`open` (default ``"wb"``).

    Yields
    ------
    file object
        The open temporary file.

    Raises
    ------
    ThermocalInputError
        The output cannot be written (permissions, full disk …); nothing was written.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> out = pathlib.Path(tempfile.mkdtemp()) / "a.txt"
    >>> with atomic_write(out, "w") as fh:
    ...     _ = fh.write("ok")
    >>> out.read_text()
    'ok'
    """
    with _temporary_for(path) as (_target, tmp), open(tmp, mode) as fh:
        yield fh


def atomic_write_path(path: str | Path, writer: Callable[[Path], None]) -> None:
    """Call ``writer(tmp_path)``, then rename ``tmp_path`` over ``path``.

    For libraries that want a path, not a file object (Arrow, matplotlib).

    Parameters
    ----------
    path : str or Path
        The output file.
    writer : callable
        ``writer(tmp_path)`` writes the whole output to ``tmp_path``.

    Raises
    ------
    ThermocalInputError
        The output cannot be written; nothing was written.
    """
    with _temporary_for(path) as (_target, tmp):
        tmp.touch(mode=0o600)
        writer(tmp)


_STAGED: list[Path] = []
"""Staging directories of this process not yet moved into place (:func:`discard_staging`)."""


def _remove_stale_staging(target: Path) -> None:
    """Remove the staging directories of ``target`` left by runs that no longer exist."""
    for cand in target.parent.glob(f".{glob.escape(target.name)}.*{TEMP_SUFFIX}"):
        middle = cand.name[len(target.name) + 2 : -len(TEMP_SUFFIX)]
        pid_text = middle.split(".", 1)[0]
        dead = pid_text.isdigit() and not _pid_alive(int(pid_text))
        if dead and cand.is_dir() and not cand.is_symlink():
            shutil.rmtree(cand, ignore_errors=True)


def staging_directory(target: str | Path) -> Path:
    """A new empty directory beside ``target`` for a set of outputs that appear whole or not at all.

    The directory is ``.NAME.<pid>.<random>.thermocal-partial``; a command builds its
    outputs (calibration, parameters, reports) in it, :func:`commit_directory` moves it
    into place, :func:`discard_staging` removes it on failure, and the next run to the
    same target removes those of runs that died.

    Parameters
    ----------
    target : str or Path
        The output directory.

    Returns
    -------
    Path
        The staging directory.

    Raises
    ------
    ThermocalInputError
        ``target`` exists and is not a directory, or its parent is not a directory.
    """
    t = Path(target)
    refuse_special(t)
    if t.exists() and not t.is_dir():
        raise ThermocalInputError(f"{target}: exists and is not a directory")
    try:
        t.parent.mkdir(parents=True, exist_ok=True)
    except (FileExistsError, NotADirectoryError):
        raise ThermocalInputError(
            f"{target}: cannot create the output, {t.parent} is not a directory"
        ) from None
    _remove_stale_staging(t)
    stage = _temp_path(t)
    stage.mkdir()
    _STAGED.append(stage)
    return stage


def commit_directory(stage: Path, target: str | Path) -> None:
    """Move a complete output set from ``stage`` into ``target``.

    One rename when ``target`` does not exist or is an empty directory (atomic);
    otherwise each file replaces its namesake in ``target`` (``os.replace``, atomic per
    file; other files of ``target`` are left alone), then ``stage`` is removed.

    Parameters
    ----------
    stage : Path
        The staging directory (:func:`staging_directory`).
    target : str or Path
        The output directory.
    """
    t = Path(target)
    with _output_lock(t):
        empty = t.is_dir() and not t.is_symlink() and not any(t.iterdir())
        if (not t.exists() and not t.is_symlink()) or empty:
            os.replace(stage, t)
        else:
            t.mkdir(parents=True, exist_ok=True)
            for f in sorted(stage.iterdir()):
                os.replace(f, t / f.name)
            stage.rmdir()
    with contextlib.suppress(ValueError):
        _STAGED.remove(stage)
    for k, w in enumerate(WRITTEN):  # name the outputs where they now are
        if w.parent == stage:
            WRITTEN[k] = t / w.name


def discard_staging() -> None:
    """Remove every staging directory of this process not moved into place."""
    while _STAGED:
        stage = _STAGED.pop()
        shutil.rmtree(stage, ignore_errors=True)
        WRITTEN[:] = [w for w in WRITTEN if w.parent != stage]


def write_html(path: str | Path, html: str) -> Path:
    """Write an HTML page (a report) atomically as UTF-8.

    Parameters
    ----------
    path : str or Path
        The output file.
    html : str
        The page.

    Returns
    -------
    Path
        ``path``.
    """
    with atomic_write(path, "wb") as fh:
        fh.write(html.encode("utf-8"))
    return Path(path)


def write_json(path: str | Path, obj: Any) -> None:
    r"""Write JSON atomically (indent 2, UTF-8, a final newline).

    Parameters
    ----------
    path : str or Path
        The output file.
    obj : object
        A JSON-serialisable object; NaN and infinities are refused (``ValueError``).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> out = pathlib.Path(tempfile.mkdtemp()) / "a.json"
    >>> write_json(out, {"bias": 1.5})
    >>> out.read_text()
    '{\n  "bias": 1.5\n}\n'
    """
    text = json.dumps(obj, indent=2, ensure_ascii=False, allow_nan=False)
    with atomic_write(path, "w") as fh:
        fh.write(text + "\n")


def check_not_input(out: str | Path, inputs: list[str | Path]) -> None:
    """Refuse to write ``out`` over an input, an input's sidecar or a special file.

    The one gate is :func:`thermocal.outputs.check_outputs`; an input is never
    overwritten.

    Parameters
    ----------
    out : str or Path
        The output file.
    inputs : list of str or Path
        The input files (each ``FILE.meta.json`` sidecar is protected too).

    Raises
    ------
    ThermocalInputError
        ``out`` is one of the inputs, an input's sidecar or a special file.
    """
    check_outputs([out], inputs)


def _write_parquet(p: Path, data: dict[str, FloatArray], info: dict[str, Any],
                   sidecar: bool | None) -> None:  # fmt: skip
    """A Parquet recording: the metadata in its key-value store (and a sidecar if asked)."""
    table = pa.table(data)
    table = table.replace_schema_metadata({META_KEY: json.dumps(info)})
    atomic_write_path(p, lambda tmp: pq.write_table(table, tmp, write_page_checksum=True))
    if sidecar:
        write_json(sidecar_path(p), info)


def _write_csv(p: Path, data: dict[str, FloatArray], info: dict[str, Any],
               sidecar: bool | None) -> None:  # fmt: skip
    """A CSV recording (Arrow's writer: shortest exact numbers) and its sidecar; gzip
    compressed when the name ends ``.gz`` (``run.csv.gz``, as the CSV reader expects)."""
    warn_formula_names(p, data)  # kept exactly: a program reads the names back
    table = pa.table(data)
    opts = pacsv.WriteOptions(include_header=True, quoting_style="needed")

    def write(tmp: Path) -> None:
        if p.name.lower().endswith(".gz"):
            with pa.CompressedOutputStream(str(tmp), "gzip") as out:
                pacsv.write_csv(table, out, write_options=opts)
        else:
            pacsv.write_csv(table, tmp, write_options=opts)

    atomic_write_path(p, write)
    if sidecar is None or sidecar:
        write_json(sidecar_path(p), info)


RecordingWriter = Callable[[Path, dict[str, FloatArray], dict[str, Any], bool | None], None]
"""``write(path, columns, metadata, sidecar)``: a recording's columns written atomically."""

RECORDING_WRITERS: dict[str, RecordingWriter] = {"parquet": _write_parquet, "csv": _write_csv}
"""The registered formats (:mod:`thermocal.readers.formats`) a recording is written in."""


def written_format(path: Path) -> str:
    """The name of the format an output recording is written in, by its suffix.

    Parameters
    ----------
    path : Path
        The output recording.

    Returns
    -------
    str
        A key of :data:`RECORDING_WRITERS` (``"csv"`` or ``"parquet"``).

    Raises
    ------
    thermocal.errors.FileFormatError
        A suffix no format has, or a format thermocal reads but does not write.

    Examples
    --------
    >>> from pathlib import Path
    >>> written_format(Path("out.parquet"))
    'parquet'
    """
    kind = file_kind(path)
    if kind not in RECORDING_WRITERS:
        raise FileFormatError(
            f"{path}: thermocal reads {format_named(kind).title} but writes recordings as CSV "
            "or Parquet; name the output *.csv or *.parquet"
        )
    return kind


def write_recording(
    rec: Recording, path: str | Path, *, time: str = "time", sidecar: bool | None = None
) -> Path:
    """Write a recording as CSV or Parquet (by extension), atomically.

    CSV files get a sidecar ``FILE.meta.json``; Parquet files carry the same JSON in
    their key-value metadata (and a sidecar only if ``sidecar=True``).
    Time is written in [s].  CSV numbers are written by Arrow's writer in their
    shortest exact form, so a CSV round-trip reproduces every float64 bit.

    Parameters
    ----------
    rec : Recording
        What to write.
    path : str or Path
        The output; its registered format (:func:`thermocal.readers.formats.file_kind`)
        chooses the writer in :data:`RECORDING_WRITERS`.
    time : str
        Name of the time column written [s].
    sidecar : bool, optional
        Write ``FILE.meta.json`` (default: for CSV only).

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    thermocal.errors.FileFormatError
        A suffix no format has, or a format thermocal reads but does not write.
    thermocal.errors.ThermocalInputError
        A column named like the time column.
    """
    p = Path(path)
    writer = RECORDING_WRITERS[written_format(p)]
    info = recording_info(rec, time=time)
    data: dict[str, FloatArray] = {time: rec.time_s}
    for c, v in rec.columns.items():
        if c == time:
            raise ThermocalInputError(f"column name {c!r} clashes with the time column")
        data[c] = v
    writer(p, data, info, sidecar)
    return p


def write_program(path: str | Path, time_s: npt.ArrayLike, setpoint_c: npt.ArrayLike) -> Path:
    """Write a chamber program CSV with columns ``time_s, setpoint_c``, atomically.

    Parameters
    ----------
    path : str or Path
        The output, ``*.csv``.
    time_s : array_like
        Times [s], increasing.
    setpoint_c : array_like
        Set-points [°C], one per time.

    Returns
    -------
    Path
        The file written (read back by :func:`thermocal.readers.program.read_program`).

    Raises
    ------
    thermocal.errors.ThermocalInputError
        Not a ``.csv`` name, or a program :func:`thermocal.profiles.check_program` refuses.
    """
    from thermocal.profiles import check_program

    t = np.asarray(time_s, dtype=np.float64)
    c = np.asarray(setpoint_c, dtype=np.float64)
    check_program(t, c, str(path))
    p = Path(path)
    if p.suffix.lower() != ".csv":
        raise ThermocalInputError(f"{p}: a chamber program is written as CSV; name it *.csv")
    df = pd.DataFrame({PROGRAM_TIME: t, PROGRAM_SETPOINT: c})
    with atomic_write(p, "w") as fh:
        df.to_csv(fh, index=False, float_format="%.10g", lineterminator="\n")
    return p
