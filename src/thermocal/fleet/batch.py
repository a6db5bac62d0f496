"""Production batches: one calibration per unit of a fleet.

A TOML configuration names the ``thermocal fit`` options once (``[fit]``, by their long names
without dashes), optional ``thermocal validate`` options (``[validate]``), optional pass/fail
limits (``[limits]``) and one ``[[unit]]`` per device: ``id``, ``modeling`` (its files) and
optionally ``validation`` (a file); paths are relative to the configuration.

Each unit is one task, :func:`run_unit`: ``thermocal fit`` and, with a validation run,
``thermocal validate`` (given the modelling files) run in the worker's process through the
command line's own entry point (so a unit gets exactly what the two commands give, options,
units and warnings included, without a process start-up per unit), in a private temporary
directory; the task returns the files' bytes and the figures. The driver (:func:`run_fleet`)
writes them under ``DIR/units/<id>/`` through a temporary directory renamed into place,
``unit.json`` last, so a unit directory either is complete or does not exist.

Figures are in each channel's data unit (the unit of its column as given: °/s, rad/s, mg,
g, m/s²…; :func:`channel_figures`), not the model's internal canonical unit (°/h, mg):
``unit.json``, the summary, the report and the limits all use it.  Raw counts converted
by a scale factor stay in the physical unit the factor gives (as ``thermocal validate``).

A rerun skips a unit only when its ``unit.json`` says ``ok`` and it is still right
(:func:`stale_reasons`): the same input contents (SHA-256 of the modelling and validation
files and their ``.meta.json`` sidecars), the same options as they apply to it (``[fit]``,
``[validate]`` if it has a validation run, ``[limits]``), the same thermocal version, and a
folder that verifies (every file's recorded SHA-256, ``calibration.json`` through the model
loader's checksum check).  Otherwise it is redone and the reason is reported (``redone``);
``force`` redoes them all.

Inputs are sacred (:func:`check_outputs`): before anything is written, the run is refused
when a path it would write, replace or delete is, or contains, one of its inputs (the
configuration, the data files and their sidecars; compared by resolved path and by inode),
or is a special file (FIFO, device, ``/proc``, ``/dev``, ``/sys``).

Where the tasks run: in this process (one worker), in local worker processes (BLAS held to one
thread each: the fits already are), or on a Dask distributed cluster (``scheduler``) — the
same function on the same inputs, so the same numbers bit for bit.

After the batch: ``DIR/summary.csv`` and ``DIR/summary.parquet`` (one row per unit: ``id``,
``status``, ``error``, ``pass``, ``fail_reasons``, and per channel ``<channel>.<figure>``)
and ``DIR/fleet.html`` (:mod:`thermocal.fleet.report`).
"""

from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import json
import logging
import math
import os
import re
import secrets
import shutil
import sys
import tempfile
import threading
import time
import warnings
from collections.abc import Callable, Generator, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Final, TypeVar, cast

from thermocal._lazy import prefetch
from thermocal.errors import ParameterError, ThermocalInputError, ThermocalWarning
from thermocal.fleet.config import FleetConfig, Limit, UnitSpec, load_config
from thermocal.fleet.report import write_fleet_report
from thermocal.fleet.stats import (
    FIGURES,
    FIT_FIGURES,
    OUTLIER_Z,
    UNITLESS,
    VALIDATION_FIGURES,
    convert_unit_label,
    outliers,
    robust_z,
    shown_unit,
)
from thermocal.pipeline.messages import error_text, json_text, jsonable, warning_lines
from thermocal.pipeline.options import FitOptions, ValidateOptions
from thermocal.readers.common import memory_budget, sha256_of

if TYPE_CHECKING:
    from multiprocessing.context import BaseContext

UNIT_FILE = "unit.json"
"""Written last in a unit's directory: its presence with ``status: ok`` marks the unit done."""
UNIT_FORMAT = "thermocal-fleet-unit"
UNIT_VERSION = 2
"""2: ``inputs`` (SHA-256 per file), ``options``, ``thermocal_version``, ``files`` with their
SHA-256, figures in the data's unit."""
CALIBRATION_FILE = "calibration.json"
VALIDATION_FILE = "validation.json"

EXIT_SOME_FAILED = 4
"""Exit status of ``thermocal fleet`` when some unit failed."""


# --- configuration ------------------------------------------------------------------------


# --- one unit -----------------------------------------------------------------------------


@dataclass(frozen=True)
class UnitTask:
    """What a worker needs for one unit (plain data: it travels to Dask workers).

    Attributes
    ----------
    unit : UnitSpec
        The unit and its files.
    fit : FitOptions
        How its model is fitted.
    validate : ValidateOptions
        How it is validated.
    """

    unit: UnitSpec
    fit: FitOptions
    validate: ValidateOptions


@dataclass
class UnitOutcome:
    """What a worker hands back for one unit: status, error, warnings, the results (``fit``
    and ``validation``, as the commands' JSON gives them), the files' bytes, seconds.

    Attributes
    ----------
    id : str
        The unit.
    status : str
        ``"ok"`` or ``"failed"``.
    error : str or None
        The ``error:`` line of a failed unit.
    warnings : list of str
        Its ``warning:`` lines.
    fit, validation : dict or None
        The results as JSON objects (the fit's and the validation's ``to_dict()``).
    files : dict of str to bytes
        The files to write, by name.
    seconds : float
        Time taken [s].
    worker : str
        The worker that did it.
    figures : dict
        Per channel, the figures of :func:`channel_figures` [the channel's data unit].
    inputs : dict of str to str or None
        SHA-256 of the unit's inputs (:func:`unit_inputs`), taken before it was fitted.
    """

    id: str
    status: str
    error: str | None = None
    warnings: list[str] = field(default_factory=list)
    fit: dict[str, Any] | None = None
    validation: dict[str, Any] | None = None
    files: dict[str, bytes] = field(default_factory=dict)
    seconds: float = 0.0
    worker: str = ""
    figures: dict[str, dict[str, Any]] = field(default_factory=dict)
    """Per channel, in the channel's data unit (:func:`channel_figures`)."""
    inputs: dict[str, str | None] = field(default_factory=dict)
    """SHA-256 of the unit's inputs, taken where it ran (the workers hash in parallel)."""


_CAPTURE_LOCK = threading.Lock()
"""A unit records the warnings of its fit and validation (:func:`warnings.catch_warnings`
changes the whole process's warning state): units of one process (a Dask worker with several
threads) take turns."""

T = TypeVar("T")


def _step(outcome: UnitOutcome, work: Callable[[], T]) -> T | None:
    """``work()`` with its warnings recorded in ``outcome.warnings`` (as the command prints
    them, :func:`thermocal.pipeline.messages.warning_lines`); a failure recorded in
    ``outcome.error`` (the command's ``error:`` text, :func:`~thermocal.pipeline.messages.
    error_text`) and None returned.  Ctrl-C is not the unit's fault: it propagates."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ThermocalWarning)
        try:
            return work()
        except Exception as exc:
            text, users = error_text(exc)
            if not users and os.environ.get("THERMOCAL_DEBUG"):
                raise
            outcome.error = text
            return None
        finally:
            outcome.warnings += warning_lines(caught)


def run_unit(task: UnitTask) -> UnitOutcome:
    """Calibrate one unit (module docstring): :func:`thermocal.pipeline.fit.fit_files` on its
    modelling files, then :func:`thermocal.pipeline.validate.validate_files` on its
    validation file (``modeling``: its first modelling file) if it has one.  Never raises
    for the unit's own faults (a missing or corrupt file, a singular design): they make a
    failed outcome whose error names the file, as the command would print it.

    Parameters
    ----------
    task : UnitTask
        The unit and the fit and validation options.

    Returns
    -------
    UnitOutcome
        ``status`` ``"ok"`` or ``"failed"`` with the command's ``error:`` text; never raises
        for the unit's own fault.
    """
    from thermocal.pipeline.fit import fit_files
    from thermocal.pipeline.validate import validate_files

    t0 = time.perf_counter()
    u = task.unit
    outcome = UnitOutcome(u.id, "failed", worker=f"{os.uname().nodename}:{os.getpid()}")
    outcome.inputs = unit_inputs(u)  # before the fit: a file changed during it is seen stale
    with (
        _CAPTURE_LOCK,
        _one_thread(),
        memory_budget(worker_memory_budget()),
        tempfile.TemporaryDirectory() as tmp,
    ):
        cal = Path(tmp) / CALIBRATION_FILE
        fitted = _step(outcome, lambda: fit_files([Path(m) for m in u.modeling], task.fit, cal))
        if fitted is not None:
            outcome.fit = jsonable(fitted.to_dict())
            outcome.files[CALIBRATION_FILE] = cal.read_bytes()
        if fitted is not None and u.validation is not None:
            opts = dataclasses.replace(task.validate, modeling=Path(u.modeling[0]))
            val = Path(u.validation)
            report = _step(outcome, lambda: validate_files(cal, val, opts))
            if report is not None:  # naming the calibration beside it, not the scratch copy
                text = json_text(_beside(report.to_dict(), str(cal), CALIBRATION_FILE))
                outcome.validation = json.loads(text)
                outcome.files[VALIDATION_FILE] = text.encode("utf-8")
        if outcome.error is None:
            try:
                outcome.figures = channel_figures(cal, outcome.validation)
                outcome.status = "ok"
            except ThermocalInputError as exc:  # the calibration just written does not load
                outcome.error = one_line_error(exc)
    outcome.seconds = time.perf_counter() - t0
    return outcome


def _beside(value: Any, scratch: str, name: str) -> Any:
    """``value`` (a validation's JSON object) with every string equal to ``scratch`` (the
    worker's temporary calibration file, deleted with its folder) replaced by ``name``: the
    calibration's file name in the unit's folder, where ``validation.json`` sits beside it."""
    if isinstance(value, dict):
        return {k: _beside(v, scratch, name) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_beside(v, scratch, name) for v in value]
    return name if value == scratch else value


_THREADPOOLS: list[tuple[int, Any]] = []
"""The threadpool controller of this process and the count of its modules when it was made."""


def _one_thread() -> Any:
    """Every thread pool (BLAS, OpenMP) loaded at the unit's start held to one thread while
    it runs, restored after (``threadpoolctl.threadpool_limits(limits=1)``).  The scan for
    the loaded libraries (≈ 1.5 ms, a walk over every shared object of the process) is
    made again only when a module was imported since the last one: in a worker running
    unit after unit, once."""
    from threadpoolctl import ThreadpoolController

    n = len(sys.modules)
    if not _THREADPOOLS or _THREADPOOLS[0][0] != n:
        _THREADPOOLS[:] = [(n, ThreadpoolController())]
    return _THREADPOOLS[0][1].limit(limits=1)


WORKER_MEMORY_SHARE: Final = 0.5
"""Share of a Dask worker's memory limit a unit's reads may use (the rest: the fit's own
arrays, the worker's baseline; the nanny ends a worker at 95 %)."""


def worker_memory_budget() -> int | None:
    """On a Dask worker: :data:`WORKER_MEMORY_SHARE` of its memory limit divided among its
    threads [bytes] (each runs a unit); elsewhere (or no limit set) None.  Asked of the
    ``distributed`` module only when it is loaded (a worker has it)."""
    dist = sys.modules.get("distributed")
    if dist is None:
        return None
    try:
        worker = dist.get_worker()
    except (ValueError, AttributeError):
        return None
    limit = getattr(getattr(worker, "memory_manager", None), "memory_limit", None)
    if not limit or not math.isfinite(float(limit)) or float(limit) <= 0:
        return None
    threads = getattr(worker, "nthreads", 1)
    n = threads if isinstance(threads, int) and threads > 0 else 1
    return int(WORKER_MEMORY_SHARE * float(limit) / n)


def _per_channel(
    obj: Mapping[str, Any] | None, names: Sequence[str]
) -> dict[str, Mapping[str, Any]]:
    """``{"channels": {name: {...}}}`` or one channel's flat dict (the only channel of
    ``names``) → ``{name: {...}}``."""
    if not obj:
        return {}
    chans = obj.get("channels")
    if isinstance(chans, Mapping):
        return {str(k): v for k, v in chans.items() if isinstance(v, Mapping)}
    return {names[0]: obj} if len(names) == 1 else {}


def one_line_error(exc: BaseException) -> str:
    """The ``error:`` text of ``exc`` on one line, as the command line prints it.

    Parameters
    ----------
    exc : BaseException
        The exception.

    Returns
    -------
    str
    """
    return " ".join(str(exc).split())


def channel_figures(
    calibration: str | Path, validation: Mapping[str, Any] | None = None
) -> dict[str, dict[str, Any]]:
    """Per channel of a calibration (or model) file: ``unit`` (the channel's data unit,
    :func:`shown_unit`), ``unit_as_given``, ``model_unit``, the fit figures
    (:data:`FIT_FIGURES`), the validation figures (:data:`VALIDATION_FIGURES`, from
    the JSON of the ``validate`` command) and ``coefficients`` ``{term: value}`` with
    ``coefficient_units``, every signal figure in ``unit``.

    The fit's figures are read from the file through the model loader (checksum verified),
    in the model's unit, and multiplied by the factor of :func:`shown_unit`; validation
    figures come in the unit that ``validate`` names and are converted the same way.

    Parameters
    ----------
    calibration : str or pathlib.Path
        The unit's calibration or model file.
    validation : mapping, optional
        Its result, as the JSON of the ``validate`` command.

    Returns
    -------
    dict of str to dict
        Per channel its figures and ``unit``.
    """
    from thermocal.pipeline.model_file import load_calibration

    cal = load_calibration(calibration)
    vals = _per_channel(validation, cal.names)
    out: dict[str, dict[str, Any]] = {}
    for ch in cal.channels:
        model = ch.model
        model_unit = str(model.signal_unit)
        unit, factor = shown_unit(model_unit, ch.unit)
        st = model.stats_
        row: dict[str, Any] = {
            "unit": unit,
            "unit_as_given": ch.unit,
            "model_unit": model_unit,
            "rms_residual": float(st.rms_residual) * factor,
            "condition_number": st.condition_number,
            "n_coefficients": st.n_coefficients,
            "n_samples": st.n_samples,
        }
        v = vals.get(ch.name, {})
        v_unit = str(v.get("unit") or unit)
        v_factor = 1.0 if v_unit == unit else shown_unit(v_unit, unit)[1]
        if v_unit != unit and shown_unit(v_unit, unit)[0] != unit:
            v = {}  # figures in a unit that cannot be shown in the channel's: left out
        for k in VALIDATION_FIGURES:
            x = v.get(k)
            if x is not None and k != "r":
                x = float(x) * v_factor
            row[k] = x
        coefs: dict[str, float] = {}
        coef_units: dict[str, str] = {}
        for c in model.coefficients():
            label = convert_unit_label(c.unit, model_unit, unit)
            coefs[c.name] = float(c.value) * (factor if label is not None else 1.0)
            coef_units[c.name] = label if label is not None else c.unit
        row["coefficients"] = coefs
        row["coefficient_units"] = coef_units
        adequacy = getattr(model, "adequacy_", None)
        if isinstance(adequacy, Mapping):
            row["adequacy"] = adequacy.get("verdict")
        out[ch.name] = row
    return out


def unit_figures(outcome: UnitOutcome) -> dict[str, dict[str, Any]]:
    """Per channel figures of an outcome, in each channel's data unit (:func:`channel_figures`).

    Parameters
    ----------
    outcome : UnitOutcome
        What the worker handed back.

    Returns
    -------
    dict of str to dict
    """
    return outcome.figures


def judge(figures: Mapping[str, Mapping[str, Any]], limits: Sequence[Limit]) -> list[str]:
    """The limits a unit fails (empty: it passes).

    Parameters
    ----------
    figures : mapping of str to mapping
        Per channel its figures in its data unit (:func:`channel_figures`), with ``"unit"``.
    limits : sequence of Limit
        The ``[limits]`` of the configuration.

    Returns
    -------
    list of str
        One line per limit failed, naming the channel, the figure, its value and unit.

    Examples
    --------
    >>> from thermocal.fleet.config import Limit
    >>> judge({"gyro": {"rms_after": 0.2, "unit": "deg/s"}}, [Limit("rms_after", "max", 0.15)])
    ['gyro.rms_after = 0.2 deg/s fails rms_after ≤ 0.15']
    >>> judge({"gyro": {"rms_after": 0.1, "unit": "deg/s"}}, [Limit("rms_after", "max", 0.15)])
    []
    """
    failed: list[str] = []
    for lim in limits:
        names = [lim.channel] if lim.channel else list(figures)
        for ch in names:
            fig = figures.get(ch or "")
            if fig is None:
                failed.append(f"{lim.label}: no channel {ch!r}")
                continue
            value = fig.get(lim.figure)
            if value is None:
                why = "no validation run" if lim.figure in VALIDATION_FIGURES else "not computed"
                failed.append(f"{ch}.{lim.figure} {why} ({lim.label})")
            elif not lim.check(float(value)):
                unit = "" if lim.figure in UNITLESS else f" {fig.get('unit') or ''}".rstrip()
                failed.append(f"{ch}.{lim.figure} = {float(value):.6g}{unit} fails {lim.label}")
    return failed


# --- the batch ----------------------------------------------------------------------------


@dataclass(frozen=True)
class FleetResult:
    """What :func:`run_fleet` did.

    Parameters
    ----------
    ran, skipped, failed : tuple of str
        Unit ids run now, skipped (done before and still right), and failed.
    rows : tuple of dict
        The summary rows of every unit of the configuration.
    summary_csv, summary_parquet, html : pathlib.Path
        The files written.
    interrupted : str, optional
        Why the batch stopped early (a worker died, the cluster went away).
    redone : mapping of str to str
        The units redone in this run and why.
    """

    ran: tuple[str, ...]
    skipped: tuple[str, ...]
    failed: tuple[str, ...]
    rows: tuple[dict[str, Any], ...]
    summary_csv: Path
    summary_parquet: Path
    html: Path
    interrupted: str | None = None
    redone: Mapping[str, str] = field(default_factory=dict)

    def counts(self) -> tuple[int, int, int]:
        """Units calibrated, failed and passed (calibrated and within every limit).

        Returns
        -------
        tuple of int
            ``(ok, failed, passed)`` over :attr:`rows`; the others are pending.
        """
        ok = sum(1 for r in self.rows if r["status"] == "ok")
        failed = sum(1 for r in self.rows if r["status"] == "failed")
        passed = sum(1 for r in self.rows if r["status"] == "ok" and r.get("pass") is True)
        return ok, failed, passed

    def summary(self, output: Path) -> dict[str, Any]:
        """The batch's outcome as JSON types.

        Parameters
        ----------
        output : pathlib.Path
            The batch's output folder, as given.

        Returns
        -------
        dict
            ``output``, the counts (``units``, ``ok``, ``failed``, ``pending``, ``passed``),
            the unit ids ``ran`` and ``skipped``, ``redone`` (id → why), ``failed_units``
            (id → error), the files written and ``interrupted``.
        """
        ok, failed, passed = self.counts()
        rows = self.rows
        return {
            "output": str(output),
            "units": len(rows),
            "ok": ok,
            "failed": failed,
            "pending": len(rows) - ok - failed,
            "passed": passed,
            "ran": list(self.ran),
            "skipped": list(self.skipped),
            "redone": dict(self.redone),
            "failed_units": {r["id"]: r["error"] for r in rows if r["status"] == "failed"},
            "summary_csv": str(self.summary_csv),
            "summary_parquet": str(self.summary_parquet),
            "report": str(self.html),
            "interrupted": self.interrupted,
        }

    def text(self) -> list[str]:
        """The batch's outcome in lines: the counts, each unit redone and why, the files.

        Returns
        -------
        list of str
        """
        ok, failed, passed = self.counts()
        return [
            f"{len(self.rows)} units: {ok} calibrated ({len(self.ran)} now, "
            f"{len(self.skipped)} done before), {failed} failed, {passed} passed",
            *(f"redone {uid}: {why}" for uid, why in self.redone.items()),
            f"summary: {self.summary_csv}, {self.summary_parquet}",
            f"report: {self.html}",
        ]


def check_workers(workers: int | None, scheduler: str | None) -> None:
    """Refuse a number of local workers below 1, or local workers with a Dask scheduler.

    Parameters
    ----------
    workers : int or None
        Local worker processes asked for (None: the default).
    scheduler : str or None
        A Dask scheduler's address (None: local processes).

    Raises
    ------
    ParameterError
        ``workers`` below 1, or both given.
    """
    if workers is not None and workers < 1:
        raise ParameterError("workers", f"{{name}} must be at least 1, got {workers}")
    if scheduler is not None and workers is not None:
        raise ParameterError("workers", "give {name} or {scheduler}, not both", ("scheduler",))


def unit_dir(out_dir: Path, uid: str) -> Path:
    """The folder of unit ``uid``: ``DIR/units/<id>``.

    Parameters
    ----------
    out_dir : pathlib.Path
        The batch's output folder.
    uid : str
        The unit's id.

    Returns
    -------
    pathlib.Path
    """
    return out_dir / "units" / uid


def read_unit(out_dir: Path, uid: str) -> dict[str, Any] | None:
    """A unit's ``unit.json`` (None when absent or unreadable: not done).

    Parameters
    ----------
    out_dir : pathlib.Path
        The batch's output folder.
    uid : str
        The unit's id.

    Returns
    -------
    dict or None
    """
    f = unit_dir(out_dir, uid) / UNIT_FILE
    try:
        obj = json.loads(f.read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):  # nested too deeply: redone too
        return None
    return obj if isinstance(obj, dict) and obj.get("format") == UNIT_FORMAT else None


# --- what a unit depends on, and whether its folder is still right --------------------------


def unit_input_paths(u: UnitSpec) -> list[str]:
    """The files a unit reads: its modelling files, its validation file, and the
    ``FILE.meta.json`` sidecar of each where one exists (it sets units and conversions).

    Parameters
    ----------
    u : UnitSpec
        The unit.

    Returns
    -------
    list of str
    """
    from thermocal.outputs import sidecar_path

    out: list[str] = []
    for f in (*u.modeling, *([u.validation] if u.validation else [])):
        out.append(f)
        side = sidecar_path(f)
        if side.exists():
            out.append(str(side))
    return out


def unit_inputs(u: UnitSpec) -> dict[str, str | None]:
    """``{path: sha256}`` of :func:`unit_input_paths` (recorded in ``unit.json``).

    Parameters
    ----------
    u : UnitSpec
        The unit.

    Returns
    -------
    dict of str to str or None
        SHA-256 of each input (None when it cannot be read).
    """
    return {f: sha256_of(f) for f in unit_input_paths(u)}


def unit_options(config: FleetConfig, u: UnitSpec) -> dict[str, Any]:
    """The options as they apply to a unit: ``fit`` (``[fit]`` as arguments), ``validate``
    (``[validate]``, only for a unit with a validation run) and ``limits``
    (``[channel, figure, bound, value]``; every limit applies to every unit: a channel
    limit on a unit without the channel fails it).

    Parameters
    ----------
    config : FleetConfig
        The batch.
    u : UnitSpec
        The unit.

    Returns
    -------
    dict
    """
    return {
        "fit": list(config.fit_args),
        "validate": list(config.validate_args) if u.validation is not None else [],
        "limits": [[lim.channel, lim.figure, lim.bound, lim.value] for lim in config.limits],
    }


def _version() -> str:
    from thermocal import __version__

    return str(__version__)


def verify_unit_folder(folder: Path, rec: Mapping[str, Any]) -> list[str]:
    """What is wrong with a unit's folder (empty: it verifies): every file ``unit.json``
    lists is present with its recorded SHA-256, and ``calibration.json`` loads through the
    model loader (format, version, checksum).

    Parameters
    ----------
    folder : pathlib.Path
        The unit's folder.
    rec : mapping
        Its ``unit.json``.

    Returns
    -------
    list of str
        What is wrong (empty: it verifies).
    """
    from thermocal.pipeline.model_file import load_calibration

    problems: list[str] = []
    files = rec.get("files")
    if not isinstance(files, Mapping) or CALIBRATION_FILE not in files:
        return ["unit.json does not list its files"]
    for name, digest in files.items():
        if not isinstance(name, str) or "/" in name or name.startswith("."):
            problems.append(f"unit.json lists a file {name!r} outside its folder")
            continue
        got = sha256_of(folder / name)
        if got is None:
            problems.append(f"{name} is missing")
        elif got != digest:
            problems.append(f"{name} changed since it was written")
    try:
        load_calibration(folder / CALIBRATION_FILE)
    except ThermocalInputError as exc:
        problems.append(f"{CALIBRATION_FILE} does not verify ({one_line_error(exc)})")
    return problems


def stale_reasons(
    out_dir: Path, config: FleetConfig, u: UnitSpec, inputs: Mapping[str, str | None]
) -> list[str] | None:
    """Why a unit must be (re)done: None for a unit never run (no folder), ``[]`` for one
    done and still right, else the reasons (module docstring).

    Parameters
    ----------
    out_dir : pathlib.Path
        The batch's output folder.
    config : FleetConfig
        The batch.
    u : UnitSpec
        The unit.
    inputs : mapping of str to str or None
        SHA-256 of the unit's inputs now.

    Returns
    -------
    list of str or None
        None: never run; empty: done and still right; else why it must be redone.
    """
    folder = unit_dir(out_dir, u.id)
    rec = read_unit(out_dir, u.id)
    if rec is None:
        if folder.exists() or folder.is_symlink():
            return ["its folder has no readable unit.json"]
        return None
    if rec.get("status") != "ok":
        return [f"it failed before ({rec.get('error') or 'no error recorded'})"]
    if rec.get("version") != UNIT_VERSION:
        return [f"its unit.json is of an older fleet format (version {rec.get('version')})"]
    reasons: list[str] = []
    if rec.get("thermocal_version") != _version():
        reasons.append(f"thermocal version changed ({rec.get('thermocal_version')} → {_version()})")
    before = rec.get("inputs") or {}
    for f, digest in inputs.items():
        if f not in before:
            reasons.append(f"input {f} is new to it")
        elif before[f] != digest:
            reasons.append(f"input {f} changed" if digest else f"input {f} cannot be read")
    for f in before:
        if f not in inputs:
            reasons.append(f"input {f} is no longer one of its inputs")
    old_opts = rec.get("options") or {}
    new_opts = unit_options(config, u)
    for key, label in (("fit", "[fit]"), ("validate", "[validate]"), ("limits", "[limits]")):
        if old_opts.get(key) != new_opts[key]:
            reasons.append(f"its {label} options changed")
    reasons += verify_unit_folder(folder, rec)
    return reasons


# --- inputs are sacred --------------------------------------------------------------------


def config_inputs(config: FleetConfig) -> list[str]:
    """Every file the batch reads: the configuration and each unit's inputs.

    Parameters
    ----------
    config : FleetConfig
        The batch.

    Returns
    -------
    list of str
    """
    out = [str(config.path)]
    for u in config.units:
        out += unit_input_paths(u)
    return out


def check_outputs(config: FleetConfig, out_dir: str | Path) -> None:
    """Refuse the run (:class:`ThermocalInputError`, exit 2, before anything is written)
    when a path the fleet writes, replaces or deletes is, or contains, one of its inputs
    (:func:`config_inputs`; compared by resolved path and by inode, so a symlink or a hard
    link to an input counts), or is a special file (FIFO, device, socket, under ``/proc``,
    ``/dev``, ``/sys``).

    The paths: ``DIR`` itself, ``DIR/summary.csv``, ``DIR/summary.parquet``,
    ``DIR/fleet.html`` (and their stale temporaries), ``DIR/units`` and, for every unit,
    ``DIR/units/<id>`` (replaced when the unit is redone) and the temporary folders of
    interrupted runs (deleted).  The rules are those of every command, one gate:
    :func:`thermocal.outputs.check_outputs`.

    Parameters
    ----------
    config : FleetConfig
        The batch.
    out_dir : str or pathlib.Path
        The batch's output folder.

    Raises
    ------
    ThermocalInputError
        An output would write over, replace or delete an input.
    """
    from thermocal.outputs import check_outputs as gate

    out = Path(out_dir)
    units = out / "units"
    gate(
        [out / name for name in ("summary.csv", "summary.parquet", "fleet.html")],
        config_inputs(config),
        dirs=[out, units],
        replaced=[*(unit_dir(out, u.id) for u in config.units), *_stale_folders(units)],
        what="the fleet output",
    )


_STALE = re.compile(r"^\.(?P<id>[A-Za-z0-9][A-Za-z0-9._-]*)\.(tmp|old)-[0-9a-f]{8}$")
"""A unit folder being written (``.<id>.tmp-<hex>``) or set aside (``.<id>.old-<hex>``)."""


def _stale_folders(units_dir: Path) -> list[Path]:
    """Temporary unit folders of an interrupted run (:data:`_STALE`)."""
    if not units_dir.is_dir():
        return []
    return sorted(p for p in units_dir.iterdir() if _STALE.match(p.name))


def _clean_stale(units_dir: Path) -> None:
    """Remove the temporary unit folders of an interrupted run (checked by
    :func:`check_outputs` to hold no input)."""
    for d in _stale_folders(units_dir):
        if d.is_symlink() or not d.is_dir():
            d.unlink(missing_ok=True)
        else:
            shutil.rmtree(d, ignore_errors=True)


def write_unit(out_dir: Path, outcome: UnitOutcome, record: dict[str, Any]) -> Path:
    """Write a unit's files into a temporary directory, ``unit.json`` last (with each
    file's SHA-256), and rename it into place (an older directory of the unit is moved
    aside first and removed after): ``units/<id>/`` is complete or absent, whenever the run
    stops.

    Parameters
    ----------
    out_dir : pathlib.Path
        The batch's output folder.
    outcome : UnitOutcome
        What the worker handed back.
    record : dict
        The unit's ``unit.json`` record.

    Returns
    -------
    pathlib.Path
        The unit's folder.
    """
    units_dir = out_dir / "units"
    units_dir.mkdir(parents=True, exist_ok=True)
    tag = secrets.token_hex(4)
    tmp = units_dir / f".{outcome.id}.tmp-{tag}"
    tmp.mkdir()
    for name, data in outcome.files.items():
        (tmp / name).write_bytes(data)
    record = {
        **record,
        "files": {n: hashlib.sha256(d).hexdigest() for n, d in sorted(outcome.files.items())},
    }
    text = json.dumps(record, indent=2, ensure_ascii=False, allow_nan=False)
    (tmp / UNIT_FILE).write_text(text + "\n", encoding="utf-8")
    final = unit_dir(out_dir, outcome.id)
    old = None
    if final.exists() or final.is_symlink():
        old = units_dir / f".{outcome.id}.old-{tag}"
        os.replace(final, old)
    os.replace(tmp, final)
    if old is not None:
        if old.is_symlink() or not old.is_dir():
            old.unlink(missing_ok=True)
        else:
            shutil.rmtree(old, ignore_errors=True)
    return final


def _finite(obj: Any) -> Any:
    """NaN/inf → None for JSON."""
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {k: _finite(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_finite(v) for v in obj]
    return obj


def unit_record(
    outcome: UnitOutcome,
    config: FleetConfig,
    *,
    inputs: Mapping[str, str | None] | None = None,
    redone_because: str | None = None,
) -> dict[str, Any]:
    """The content of ``unit.json``: status, error, warnings, figures per channel (in each
    channel's data unit), pass/fail against the limits, what the unit was made from
    (``inputs`` with their SHA-256, ``options``, ``thermocal_version``), why it was redone,
    and timing.  :func:`write_unit` adds ``files`` (name → SHA-256).

    Parameters
    ----------
    outcome : UnitOutcome
        What the worker handed back.
    config : FleetConfig
        The batch.
    inputs : mapping, optional
        SHA-256 of the unit's inputs.
    redone_because : str, optional
        Why the unit was redone.

    Returns
    -------
    dict
    """
    spec = next((u for u in config.units if u.id == outcome.id), None)
    figures = unit_figures(outcome) if outcome.status == "ok" else {}
    reasons = judge(figures, config.limits) if outcome.status == "ok" else []
    passed: bool | None = None
    if outcome.status == "ok":
        passed = not reasons
    if inputs is None and spec is not None:
        inputs = unit_inputs(spec)
    record: dict[str, Any] = _finite(
        {
            "format": UNIT_FORMAT,
            "version": UNIT_VERSION,
            "id": outcome.id,
            "status": outcome.status,
            "error": outcome.error,
            "pass": passed if config.limits else (True if outcome.status == "ok" else None),
            "fail_reasons": reasons,
            "warnings": outcome.warnings,
            "channels": figures,
            "inputs": dict(inputs or {}),
            "options": unit_options(config, spec) if spec is not None else {},
            "thermocal_version": _version(),
            "redone_because": redone_because,
            "seconds": outcome.seconds,
            "worker": outcome.worker,
            "finished_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        }
    )
    return record


def summary_rows(
    config: FleetConfig,
    out_dir: Path,
    redone: Mapping[str, str] | None = None,
    stale: Mapping[str, str] | None = None,
    records: Mapping[str, dict[str, Any] | None] | None = None,
) -> list[dict[str, Any]]:
    """One row per unit of the configuration, from the units' ``unit.json`` (a unit with
    none, or found stale and not redone (``stale``: an interrupted run): ``status``
    ``pending``); ``redone``: the reason a unit was redone in this run.

    Parameters
    ----------
    config : FleetConfig
        The batch.
    out_dir : pathlib.Path
        The batch's output folder.
    redone : mapping, optional
        Units redone in this run and why.
    stale : mapping, optional
        Units found stale and not redone (pending).
    records : mapping, optional
        The units' ``unit.json`` already read (:func:`read_unit`, by id); None: read here.

    Returns
    -------
    list of dict
    """
    rows: list[dict[str, Any]] = []
    redone = redone or {}
    stale = stale or {}
    for u in config.units:
        rec = records[u.id] if records is not None else read_unit(out_dir, u.id)
        row: dict[str, Any] = {"id": u.id}
        if rec is None or u.id in stale:
            why = "not run yet" if rec is None else f"to be redone: {stale[u.id]}"
            row.update(status="pending", error=why, **{"pass": None})
            row["fail_reasons"] = ""
            row["redone"] = ""
            rows.append(row)
            continue
        row.update(
            status=rec.get("status"),
            error=rec.get("error"),
            **{"pass": rec.get("pass")},
        )
        row["fail_reasons"] = "; ".join(rec.get("fail_reasons") or [])
        row["redone"] = redone.get(u.id, "")
        row["seconds"] = rec.get("seconds")
        row["n_warnings"] = len(rec.get("warnings") or [])
        for ch, fig in (rec.get("channels") or {}).items():
            row[f"{ch}.unit"] = fig.get("unit")
            for k in FIGURES:
                row[f"{ch}.{k}"] = fig.get(k)
        rows.append(row)
    return rows


def write_summary(rows: Sequence[Mapping[str, Any]], out_dir: Path) -> tuple[Path, Path]:
    """``summary.csv`` and ``summary.parquet`` (atomic writes), columns in first-seen order.

    ``summary.csv`` is a table for spreadsheets: a text cell or a column name beginning
    with ``=``, ``+``, ``-``, ``@``, TAB or CR (a unit id, a channel name, an error) is
    written with a ``'`` in front, so that the spreadsheet shows it instead of running it
    as a formula (OWASP, "CSV Injection",
    https://owasp.org/www-community/attacks/CSV_Injection;
    :func:`thermocal.outputs.neutralise_cell`); numbers stay numbers.
    ``summary.parquet`` keeps every name and text exactly.

    Parameters
    ----------
    rows : sequence of mapping
        The rows (:func:`summary_rows`).
    out_dir : pathlib.Path
        The batch's output folder.

    Returns
    -------
    tuple of pathlib.Path
        ``summary.csv`` and ``summary.parquet``.
    """
    import pandas as pd

    from thermocal.writers import atomic_write, atomic_write_path

    columns: list[str] = []
    for r in rows:
        columns += [c for c in r if c not in columns]
    df = pd.DataFrame([{c: r.get(c) for c in columns} for r in rows], columns=columns)
    for c in columns:  # numbers stay numbers (a column of None is left as objects)
        if c.split(".")[-1] in FIGURES or c == "seconds":
            df[c] = pd.to_numeric(df[c], errors="coerce")
    df["pass"] = df["pass"].astype("boolean")
    csv_path, pq_path = out_dir / "summary.csv", out_dir / "summary.parquet"
    with atomic_write(csv_path, "w") as fh:
        _for_spreadsheets(df).to_csv(fh, index=False)
    atomic_write_path(pq_path, lambda tmp: df.to_parquet(tmp, index=False))
    return csv_path, pq_path


def _for_spreadsheets(df: Any) -> Any:
    """A copy of ``df`` whose text cells and column names cannot run as spreadsheet
    formulas (:func:`thermocal.outputs.neutralise_cell`; numbers and booleans untouched)."""
    from thermocal.outputs import neutralise_cell

    out = df.copy()
    for c in out.columns:
        if out[c].dtype == object:
            out[c] = out[c].map(neutralise_cell)
    out.columns = [neutralise_cell(c) for c in out.columns]
    return out


Executor = Callable[[list[UnitTask]], Iterator[UnitOutcome]]


def _fit_options(config: FleetConfig) -> FitOptions:
    """The ``[fit]`` options every unit runs (a configuration from :func:`load_config` has
    them)."""
    if config.fit is None:
        raise ThermocalInputError(f"{config.path}: no [fit] options")
    return config.fit


class _OwnedSpawnContext:
    """A ``spawn`` multiprocessing context that keeps the worker processes it starts, so that
    the driver can end them itself (:meth:`terminate`) without reaching into the pool: the
    ``mp_context`` of :class:`concurrent.futures.ProcessPoolExecutor` is a public parameter,
    and the pool starts its workers through the context's ``Process``."""

    def __init__(self) -> None:
        import multiprocessing

        self._ctx = multiprocessing.get_context("spawn")  # no fork of a threaded parent
        self.processes: list[Any] = []

    def Process(self, *args: Any, **kwargs: Any) -> Any:
        proc = self._ctx.Process(*args, **kwargs)
        self.processes.append(proc)
        return proc

    def __getattr__(self, name: str) -> Any:
        return getattr(self._ctx, name)

    def terminate(self) -> None:
        """End every worker still running (SIGTERM)."""
        for proc in self.processes:
            if proc.is_alive():
                proc.terminate()


def local_executor(
    workers: int, unit_fn: Callable[[UnitTask], UnitOutcome] | None = None
) -> Executor:
    """Units in this process (one worker) or in ``workers`` local processes, results as
    they finish.  A worker process that dies (the kernel's OOM killer, a crash in a native
    library) breaks the pool: the units it may have held (the first ``workers + 1``
    unfinished ones in submission order: the pool queues at most one call beyond its
    workers) are rerun one by one, each alone in a fresh process, and the one that kills
    its process again is a failed unit whose error names it and its files
    (:func:`lost_unit`, as on Dask); the rest go on in a fresh pool.  ``unit_fn``: what a
    worker runs per unit (default :func:`run_unit`; a module-level function, it is
    pickled).

    Parameters
    ----------
    workers : int
        Worker processes.
    unit_fn : callable, optional
        Runs one unit (default :func:`run_unit`).

    Returns
    -------
    callable
        Maps the tasks to their outcomes, as they finish.
    """
    fn = run_unit if unit_fn is None else unit_fn

    def run(tasks: list[UnitTask]) -> Iterator[UnitOutcome]:
        if workers <= 1:
            for t in tasks:
                yield fn(t)
            return
        left = list(tasks)
        while left:
            left = yield from _pool_round(left, workers, fn)

    return run


def _pool(workers: int) -> tuple[Any, Any]:
    from concurrent.futures import ProcessPoolExecutor

    ctx = _OwnedSpawnContext()
    pool = ProcessPoolExecutor(
        max_workers=workers,
        mp_context=cast("BaseContext", ctx),  # a spawn context by delegation
        initializer=_ignore_interrupts,
    )
    return ctx, pool


def _pool_round(
    tasks: list[UnitTask], workers: int, fn: Callable[[UnitTask], UnitOutcome]
) -> Generator[UnitOutcome, None, list[UnitTask]]:
    """Run ``tasks`` in one pool of ``workers`` processes; when a worker dies, settle the
    units it may have held alone (:func:`_alone`) and return those never started."""
    from concurrent.futures import FIRST_COMPLETED, wait
    from concurrent.futures.process import BrokenProcessPool

    ctx, pool = _pool(workers)
    task_of = {pool.submit(fn, t): t for t in tasks}
    pending, finished, broken = set(task_of), set(), False
    try:
        while pending and not broken:
            done, pending = wait(pending, return_when=FIRST_COMPLETED)
            for fut in done:
                try:
                    outcome = fut.result()
                except BrokenProcessPool:
                    broken = True
                    continue
                finished.add(task_of[fut].unit.id)
                yield outcome
    except BaseException:
        # Ctrl-C (or a failure): the units running are abandoned, not waited for; they
        # were never written, so a rerun does them
        pool.shutdown(wait=False, cancel_futures=True)
        ctx.terminate()
        raise
    if not broken:
        pool.shutdown(wait=True)
        return []
    pool.shutdown(wait=False, cancel_futures=True)
    ctx.terminate()
    unfinished = [t for t in task_of.values() if t.unit.id not in finished]
    for t in unfinished[: workers + 1]:
        yield _alone(t, fn)
    return unfinished[workers + 1 :]


def _alone(task: UnitTask, fn: Callable[[UnitTask], UnitOutcome]) -> UnitOutcome:
    """``task`` alone in a fresh worker process: its outcome, or :func:`lost_unit` when it
    kills that process too."""
    from concurrent.futures.process import BrokenProcessPool

    ctx, pool = _pool(1)
    try:
        return cast("UnitOutcome", pool.submit(fn, task).result())
    except BrokenProcessPool as exc:
        return lost_unit(task, exc)
    finally:
        pool.shutdown(wait=False, cancel_futures=True)
        ctx.terminate()


def _ignore_interrupts() -> None:
    """Worker processes leave Ctrl-C to the driver (it stops the batch and ends them)."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)


FORCED: Final = "--force"  # cli-words: the reason the summary records, as the command was asked
"""Why a unit already calibrated was done again when no input changed (the batch's ``force``)."""

SCHEDULER_SCHEMES: Final = ("tcp", "tls", "ws", "wss", "ucx")
"""The address schemes of a Dask scheduler address (``tcp`` when none)."""

_ADDRESS = re.compile(
    r"^(?:(?P<scheme>[a-z]+)://)?(?P<host>\[[0-9A-Fa-f:.]+\]|[^\s:/\[\]]+):(?P<port>\d{1,5})/?$"
)


def check_scheduler(address: str) -> str:
    """``address`` when it is a scheduler address ``[SCHEME://]HOST:PORT`` (a scheme of
    :data:`SCHEDULER_SCHEMES`, a port 1–65535), else a :class:`ThermocalInputError` naming
    ``scheduler`` (Dask's own parser raised ``ValueError``: exit 1).

    Parameters
    ----------
    address : str
        A Dask scheduler's address (``tcp://host:8786``).

    Returns
    -------
    str

    Raises
    ------
    ThermocalInputError
        Not ``[SCHEME://]HOST:PORT``.
    """
    m = _ADDRESS.match(address.strip())
    port = int(m.group("port")) if m else 0
    scheme = (m.group("scheme") if m else None) or "tcp"
    if m is None or not 1 <= port <= 65535 or scheme not in SCHEDULER_SCHEMES:
        raise ThermocalInputError.naming(
            f"{{scheduler}} {address!r}: not a scheduler address; give tcp://HOST:PORT (the "
            f"address `dask scheduler` prints; schemes {', '.join(SCHEDULER_SCHEMES)}, port "
            "1-65535)",
            "scheduler",
        )
    return address.strip()


def dask_executor(address: str) -> Executor:
    """Units on a Dask distributed cluster (``tcp://HOST:PORT``), results as they finish.
    Workers must read the unit's files at the same paths (a shared file system); the
    results travel back to this process, which writes them.  The address is checked
    (:func:`check_scheduler`) and the connection made here, before the batch writes
    anything.  A worker that dies running a unit (the nanny ended it: memory, a crash)
    fails that unit, its files named (:func:`lost_unit`); the others go on.

    Parameters
    ----------
    address : str
        A Dask scheduler's address (``tcp://host:8786``).

    Returns
    -------
    callable
        Maps the tasks to their outcomes, as they finish.

    Raises
    ------
    ThermocalInputError
        Dask is not installed, the address is not a scheduler's, or it cannot be reached.
    """
    import importlib

    address = check_scheduler(address)
    try:
        distributed: Any = importlib.import_module("distributed")  # untyped: held as Any
    except ImportError:
        raise ThermocalInputError.naming(
            "{scheduler} needs Dask distributed: pip install 'thermocal[fleet]'", "scheduler"
        ) from None
    try:
        with dask_logs_quiet():
            client = distributed.Client(address, timeout=30)
    except (OSError, TimeoutError, ValueError) as exc:
        msg = " ".join(str(exc).split())
        raise ThermocalInputError.naming(
            f"{{scheduler}} {address}: cannot connect ({msg})", "scheduler"
        ) from None

    def run(tasks: list[UnitTask]) -> Iterator[UnitOutcome]:
        with dask_logs_quiet():
            yield from _run_on(client, distributed, tasks)

    return run


@contextlib.contextmanager
def dask_logs_quiet() -> Iterator[None]:
    """Dask's loggers (``distributed``, ``tornado``) held silent in this process while the
    batch talks to the cluster: their records (a lost connection's traceback, a worker's
    death) went to stderr beside the command's own lines; what they report reaches the
    user as a failed unit (:func:`lost_unit`) or the batch's ``interrupted`` line."""
    names = [
        n
        for n in ("distributed", "tornado", *logging.root.manager.loggerDict)
        if n.split(".")[0] in ("distributed", "tornado")
    ]  # Dask's configuration gives some children their own level (distributed.client)
    loggers = [logging.getLogger(n) for n in dict.fromkeys(names)]
    saved = [(lg, lg.level) for lg in loggers]
    for lg in loggers:
        lg.setLevel(logging.CRITICAL + 10)
    try:
        yield
    finally:
        for lg, level in saved:
            lg.setLevel(level)


def _run_on(client: Any, distributed: Any, tasks: list[UnitTask]) -> Iterator[UnitOutcome]:
    """The units on ``client``'s cluster, as they finish (:func:`dask_executor`)."""
    try:
        keys = [f"thermocal-unit-{t.unit.id}-{secrets.token_hex(4)}" for t in tasks]
        futures = client.map(run_unit, tasks, pure=False, key=keys)
        task_of = {f.key: t for f, t in zip(futures, tasks, strict=True)}
        for fut in distributed.as_completed(futures):
            try:
                yield fut.result()
            except Exception as exc:
                if "distributed" not in type(exc).__module__:
                    raise
                yield lost_unit(task_of[fut.key], exc)
    finally:
        client.close()


def lost_unit(task: UnitTask, exc: BaseException) -> UnitOutcome:
    """The failed outcome of a unit whose worker died under it (Dask's ``KilledWorker``):
    the error names the unit's files, the likely cause and the way out.

    Parameters
    ----------
    task : UnitTask
        The unit and its options.
    exc : BaseException
        The exception.

    Returns
    -------
    UnitOutcome
        ``status`` ``"failed"`` with the reason.
    """
    u = task.unit
    files = ", ".join((*u.modeling, *((u.validation,) if u.validation else ())))
    reason = " ".join(str(exc).split())[:200]
    return UnitOutcome(
        task.unit.id,
        "failed",
        error=(
            f"the worker running unit {task.unit.id} died while it read or fitted {files} "
            f"({type(exc).__name__}: {reason}); a file too large for the worker's memory is "
            "the usual cause: cut it, or give the workers more memory"
        ),
    )


def _plan(
    config: FleetConfig, out: Path, force: bool
) -> tuple[list[UnitTask], list[str], dict[str, str], dict[str, dict[str, str | None]]]:
    """What :func:`run_fleet` does with each unit: the tasks to run, the units skipped (done
    and still right), why each unit run before is redone, and the input digests taken
    (a unit never run is hashed where it runs)."""
    todo: list[UnitTask] = []
    skipped: list[str] = []
    redo: dict[str, str] = {}
    inputs: dict[str, dict[str, str | None]] = {}
    for u in config.units:
        folder = unit_dir(out, u.id)
        if not (folder.exists() or folder.is_symlink()):
            todo.append(UnitTask(u, _fit_options(config), config.validate))
            continue
        inputs[u.id] = unit_inputs(u)
        reasons = stale_reasons(out, config, u, inputs[u.id])
        if reasons is not None and not reasons and not force:
            skipped.append(u.id)
            continue
        if reasons is not None:
            redo[u.id] = "; ".join(reasons) if reasons else FORCED
        todo.append(UnitTask(u, _fit_options(config), config.validate))
    return todo, skipped, redo, inputs


def run_fleet(
    config: FleetConfig,
    out_dir: str | Path,
    *,
    workers: int = 1,
    scheduler: str | None = None,
    force: bool = False,
    on_unit: Callable[[UnitOutcome], None] | None = None,
    executor: Executor | None = None,
) -> FleetResult:
    """Calibrate every unit not yet done or no longer right (all with ``force``), write
    each as it finishes, then the summary and ``fleet.html`` (module docstring).  A unit's
    fault never stops the others; an interrupted batch (Ctrl-C, a worker that died) keeps
    every unit written so far, writes the summary and re-raises (``KeyboardInterrupt``) or
    reports it in ``interrupted``.

    Parameters
    ----------
    config : FleetConfig
        The batch (:func:`thermocal.fleet.config.load_config`).
    out_dir : str or pathlib.Path
        The folder: ``units/<id>/``, ``summary.csv``, ``summary.parquet``, ``fleet.html``.
    workers : int
        Local worker processes (1: in this process).
    scheduler : str, optional
        Address of a Dask scheduler (``tcp://host:8786``) instead of local processes.
    force : bool
        Redo every unit, even those done and still right.
    on_unit, executor : callable, optional
        Called with each :class:`UnitOutcome` once written (progress); runs the tasks
        instead of the local or Dask executor (tests).

    Returns
    -------
    FleetResult

    Raises
    ------
    ThermocalInputError
        An output is, or holds, an input (:func:`check_outputs`, before anything is
        written); the output exists and is not a directory; the scheduler's address is
        not one.
    """
    out = Path(out_dir)
    check_outputs(config, out)
    if out.exists() and not out.is_dir():
        raise ThermocalInputError(f"{out}: exists and is not a directory")
    run = executor or (dask_executor(scheduler) if scheduler else local_executor(workers))
    out.mkdir(parents=True, exist_ok=True)
    _clean_stale(out / "units")
    todo, skipped, redo, inputs = _plan(config, out, force)
    ran: list[str] = []
    failed: list[str] = []
    interrupted: str | None = None
    try:
        if workers > 1 or scheduler:  # the driver waits for the workers meanwhile
            prefetch("pandas", "matplotlib.figure")  # for the summary and the report
        for outcome in run(todo):
            hashed = inputs.get(outcome.id) or outcome.inputs or None
            record = unit_record(
                outcome, config, inputs=hashed, redone_because=redo.get(outcome.id)
            )
            write_unit(out, outcome, record)
            ran.append(outcome.id)
            if outcome.status != "ok":
                failed.append(outcome.id)
            if on_unit is not None:
                on_unit(outcome)
    except KeyboardInterrupt:
        _finish(config, out, redo, ran)
        raise
    except Exception as exc:  # a worker process died, the cluster went away
        from concurrent.futures.process import BrokenProcessPool

        if not isinstance(exc, BrokenProcessPool) and "distributed" not in type(exc).__module__:
            raise
        left = [t.unit.id for t in todo if t.unit.id not in ran]
        interrupted = (
            f"the batch stopped: {type(exc).__name__}: {exc}; {len(left)} unit(s) not done "
            f"({', '.join(left[:10])}{', …' if len(left) > 10 else ''}): rerun to resume"
        )
    rows, csv_path, pq_path, html = _finish(config, out, redo, ran)
    return FleetResult(
        tuple(ran),
        tuple(skipped),
        tuple(failed),
        tuple(rows),
        csv_path,
        pq_path,
        html,
        interrupted,
        {k: v for k, v in redo.items() if k in ran},
    )


def _finish(
    config: FleetConfig, out: Path, redo: Mapping[str, str], ran: Sequence[str]
) -> tuple[list[dict[str, Any]], Path, Path, Path]:
    """The summary and the report; units found stale and not redone (an interrupted run)
    are pending, never shown with their old figures."""
    done = set(ran)
    redone = {k: v for k, v in redo.items() if k in done}
    stale = {k: v for k, v in redo.items() if k not in done}
    read = {u.id: read_unit(out, u.id) for u in config.units}  # each unit.json read once
    rows = summary_rows(config, out, redone, stale, read)
    csv_path, pq_path = write_summary(rows, out)
    records = {uid: (None if uid in stale else rec) for uid, rec in read.items()}
    html = write_fleet_report(out / "fleet.html", config, records, redone=redone)
    return rows, csv_path, pq_path, html


__all__ = [
    "EXIT_SOME_FAILED",
    "FIGURES",
    "FIT_FIGURES",
    "OUTLIER_Z",
    "VALIDATION_FIGURES",
    "FleetConfig",
    "FleetResult",
    "Limit",
    "UnitOutcome",
    "UnitSpec",
    "UnitTask",
    "channel_figures",
    "check_outputs",
    "check_workers",
    "dask_executor",
    "judge",
    "load_config",
    "local_executor",
    "outliers",
    "read_unit",
    "robust_z",
    "run_fleet",
    "run_unit",
    "shown_unit",
    "stale_reasons",
    "summary_rows",
    "unit_figures",
    "write_summary",
    "write_unit",
]
