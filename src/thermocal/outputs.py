"""Where a command may write: the one gate every output passes before anything is written
(the common rule of the command line: nothing is ever written over an input file).

:func:`check_outputs` refuses (:class:`~thermocal.errors.ThermocalInputError`, exit 2, one
``error:`` line naming the output and the input) when

* a file the command writes or replaces **is** one of its inputs or an input's metadata
  sidecar ``FILE.meta.json``: compared by resolved path (so a symbolic link to an input, or
  a path through a linked folder, counts) and by inode (so a hard link counts);
* a folder the command replaces or deletes (``replaced``) is, or **contains**, an input (by
  resolved path, and by the inode of every entry under it, links not followed).  A folder
  the command only writes into (``dirs``: ``export-c``, the tempcal commands, ``demo``) may
  hold inputs: the files it would write there are checked one by one;
* a temporary of an output (``.NAME.<pid>.<random>.thermocal-partial`` beside it, see
  :data:`thermocal.outputs.TEMP_SUFFIX`), which a later run removes, is or holds an input;
* the output is a **special file** (:func:`special_reason`): a FIFO, a character or block
  device, a socket, anything under ``/proc``, ``/dev`` or ``/sys``, or a symbolic link whose
  chain passes through them (a link to ``/proc/self/fd/1``, ``/dev/stdout`` itself).  The
  writers rename a finished temporary over the output, which would replace the special file
  by a regular one (as root even ``/dev/stdout`` or ``/dev/null``) instead of writing into
  it.  ``/dev/null`` is refused like every other device: the simplest rule, and one that
  cannot go wrong as root; to discard results, write them into a temporary folder.

Files the command writes that do not exist yet and hold no input pass.  The check runs
before the first byte is written; :func:`thermocal.writers.atomic_write` and
:func:`thermocal.writers.staging_directory` repeat the special-file part for every file they
open, as a backstop.
"""

from __future__ import annotations

import glob
import os
import stat
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from thermocal.errors import ThermocalInputError

SPECIAL_ROOTS = (Path("/proc"), Path("/dev"), Path("/sys"))
"""File systems that are not storage: never an output."""


@dataclass(frozen=True)
class _Input:
    label: str
    """How the error names it: ``the input file X`` or ``the metadata sidecar of …``."""
    resolved: Path
    inode: tuple[int, int] | None


def _inode(path: Path, follow: bool = True) -> tuple[int, int] | None:
    """(device, inode) of ``path``, or None when it does not exist."""
    try:
        st = os.stat(path, follow_symlinks=follow)
    except OSError:
        return None
    return (st.st_dev, st.st_ino)


def _link_chain(path: Path) -> list[Path]:
    """``path`` (absolute, not resolved) and every path its symbolic links lead through
    (``out/fleet.html`` → ``/proc/self/fd/1`` → ``/dev/pts/0``…), the resolved one last."""
    chain = [Path(os.path.abspath(path))]
    p = chain[0]
    for _ in range(40):
        # the link of the first component that is one (a folder or the file itself)
        hop = None
        for i in range(1, len(p.parts) + 1):
            head = Path(*p.parts[:i])
            if head.is_symlink():
                try:
                    target = os.readlink(head)
                except OSError:
                    break
                hop = Path(os.path.normpath(head.parent / target)).joinpath(*p.parts[i:])
                break
        if hop is None or hop in chain:
            break
        chain.append(hop)
        p = hop
    chain.append(path.resolve())
    return chain


def special_reason(path: str | Path) -> str | None:
    """Why ``path`` is no place for an output, or None.

    Only ``stat`` and ``readlink`` are used: a FIFO is never opened.

    Parameters
    ----------
    path : str or pathlib.Path
        The output's path, existing or not.

    Returns
    -------
    str or None
        ``"it is under /dev, not a storage file system"`` when the path, or a link it leads
        through, lies under :data:`SPECIAL_ROOTS`; ``"it is a FIFO"`` (a character or
        block device, a socket) from :func:`special_mode`; None for a regular file, a
        directory or nothing there.

    Examples
    --------
    >>> special_reason("/dev/null")
    'it is under /dev, not a storage file system'
    """
    p = Path(path)
    for hop in _link_chain(p):
        for root in SPECIAL_ROOTS:
            if hop == root or hop.is_relative_to(root):
                return f"it is under {root}, not a storage file system"
    return special_mode(p)


def special_mode(p: Path) -> str | None:
    """What kind of special file ``p`` is, from ``stat`` alone (never opened).

    Parameters
    ----------
    p : pathlib.Path
        The path to look at.

    Returns
    -------
    str or None
        ``"it is a FIFO"``, ``"it is a character device"``, ``"it is a block device"`` or
        ``"it is a socket"``; None for a regular file, a directory or nothing there.
    """
    try:
        mode = os.stat(p).st_mode
    except (OSError, ValueError):
        return None
    for test, what in (
        (stat.S_ISFIFO, "a FIFO"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISSOCK, "a socket"),
    ):
        if test(mode):
            return f"it is {what}"
    return None


def refuse_special_input(path: str | Path, what: str = "input file") -> None:
    """Refuse an input that is a FIFO, a device or a socket (``stat`` only: never opened).

    Reading one blocks until a writer comes, or never ends (``/dev/zero``): every reader of
    a user's path asks here first (a FIFO given as a fleet's modelling file would hang
    ``thermocal fleet``).

    Parameters
    ----------
    path : str or pathlib.Path
        The input's path.
    what : str
        How the message names the input (``"input file"``).

    Raises
    ------
    ThermocalInputError
        ``path`` is a special file; the message names it.
    """
    why = special_mode(Path(path))
    if why is not None:
        raise ThermocalInputError(
            f"{path}: {why}, not a regular file: give the {what} itself (a special file "
            "would block the read or never end)"
        )


def refuse_special(path: str | Path, what: str = "the output") -> None:
    """Refuse to write an output onto a special file (:func:`special_reason`).

    Parameters
    ----------
    path : str or pathlib.Path
        The output's path.
    what : str
        How the message names the output (``"the output"``).

    Raises
    ------
    ThermocalInputError
        ``path`` is, or leads through a link to, a special file.
    """
    why = special_reason(path)
    if why is not None:
        raise ThermocalInputError(f"{path}: refusing to write {what} there: {why}")


def _parts(resolved: Path) -> tuple[str, ...]:
    """The components of a resolved path as ``is_relative_to`` compares them (case folded
    where the system folds case), for a comparison by tuple prefix."""
    return tuple(os.path.normcase(part) for part in resolved.parts)


def _inputs(inputs: Iterable[str | Path]) -> list[_Input]:
    from thermocal.outputs import sidecar_path

    out = []
    for given in inputs:
        p = Path(given)
        out.append(_Input(f"the input file {given}", p.resolve(), _inode(p)))
        side = sidecar_path(p)
        out.append(
            _Input(f"the metadata sidecar of the input file {given}", side.resolve(), _inode(side))
        )
    return out


_STATION_JSON = "station.json"  # thermocal.readers.station.STATION_JSON (no upward import)


def _station_folders(inputs: Iterable[str | Path]) -> list[Path]:
    """The station recording folders among the inputs (``DIR`` or ``DIR/SENSOR``), resolved:
    nothing may be written inside one, where a file could become part of the recording."""
    out = []
    for given in inputs:
        p = Path(given)
        for d in (p, p.parent):
            if d.is_dir() and (d / _STATION_JSON).is_file():
                out.append(d.resolve())
                break
    return out


def _temporaries(target: Path) -> list[Path]:
    """The temporaries of ``target`` (files or staging folders) a later run removes."""
    from thermocal.outputs import TEMP_SUFFIX

    parent = target.parent
    if not parent.is_dir():
        return []
    return sorted(parent.glob(f".{glob.escape(target.name)}.*{TEMP_SUFFIX}"))


def check_outputs(
    outputs: Iterable[str | Path],
    inputs: Iterable[str | Path],
    *,
    dirs: Iterable[str | Path] = (),
    replaced: Iterable[str | Path] = (),
    what: str = "the output",
) -> None:
    """Refuse outputs that would write, replace or delete an input, or land on a special file.

    Parameters
    ----------
    outputs, inputs : iterable of str or pathlib.Path
        Files the run writes (replacing any of that name); files and station folders it reads.
    dirs, replaced : iterable of str or pathlib.Path
        Folders the run writes files into (they may hold inputs); folders it replaces or
        deletes (they may hold no input).
    what : str
        How the message names the outputs.

    Raises
    ------
    ThermocalInputError
        A rule is broken; the message names the output and the input.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     run = pathlib.Path(tmp, "run.csv")
    ...     check_outputs([pathlib.Path(tmp, "out.csv")], [run])  # a new file: passes
    ...     try:
    ...         check_outputs([run], [run])
    ...     except ThermocalInputError as err:
    ...         print(str(err).replace(tmp, "TMP"))
    TMP/run.csv: refusing to write over the input file TMP/run.csv
    """
    ins = _inputs(inputs)
    by_inode: dict[tuple[int, int] | None, _Input] = {
        i.inode: i for i in ins if i.inode is not None
    }

    stations = _station_folders(inputs)
    in_parts = [(i, _parts(i.resolved)) for i in ins]  # a batch: units x inputs comparisons
    by_path: dict[Path, _Input] = {}
    for i in ins:
        by_path.setdefault(i.resolved, i)  # the first input of that path names it

    def refuse(target: Path, why: str) -> None:
        raise ThermocalInputError(f"{target}: refusing to write {what} there: {why}")

    def not_input(target: Path, folder: bool = False) -> None:
        why = special_reason(target)
        if why is not None:
            refuse(target, why)
        r = target.resolve()
        inside = next((d for d in stations if r.is_relative_to(d)), None)
        if inside is not None:
            refuse(target, f"it is inside the input station recording {inside}")
        hit = by_path.get(r)
        link = ""
        if hit is None and target.exists():
            hit = by_inode.get(_inode(target))
            link = " (the same file: a hard link)"
        if hit is not None and folder:
            refuse(target, f"it is {hit.label}{link}, not a directory")
        if hit is not None:
            raise ThermocalInputError(f"{target}: refusing to write over {hit.label}{link}")

    def holds_no_input(folder: Path, is_dir: bool = True) -> None:
        """``folder`` is replaced or deleted: no input may be in it."""
        not_input(folder, folder=is_dir)
        r = folder.resolve()
        top = _parts(r)
        for i, parts in in_parts:
            if parts[: len(top)] == top:  # inside (or equal to) the folder
                refuse(folder, f"it contains {i.label}, which would be deleted")
        if not folder.is_dir():
            return
        for root, subdirs, files in os.walk(r):
            for name in (*files, *subdirs):
                hit = by_inode.get(_inode(Path(root) / name, follow=False))
                if hit is not None:
                    refuse(folder, f"it holds {Path(root) / name}, which is {hit.label}")

    def no_stale_input(target: Path) -> None:
        for tmp in _temporaries(target):
            holds_no_input(tmp, is_dir=False)

    for d in (Path(x) for x in dirs):
        not_input(d, folder=True)
        if d.exists() and not d.is_dir():
            raise ThermocalInputError(f"{d}: exists and is not a directory")
        no_stale_input(d)
    for d in (Path(x) for x in replaced):
        holds_no_input(d)
        if d.exists() and not d.is_dir():
            raise ThermocalInputError(f"{d}: exists and is not a directory")
        no_stale_input(d)
    for f in (Path(x) for x in outputs):
        not_input(f)
        if f.is_dir():
            raise ThermocalInputError(f"{f}: is a directory, expected a file name")
        no_stale_input(f)


FORMULA_TRIGGERS: tuple[str, ...] = ("=", "+", "-", "@", "\t", "\r")
"""First characters that make a spreadsheet (Excel, LibreOffice Calc, Google Sheets) read
a CSV cell as a formula: OWASP, "CSV Injection"
(https://owasp.org/www-community/attacks/CSV_Injection) and ASVS 5.0 requirement 1.2.10
list ``=``, ``+``, ``-``, ``@``, TAB and CR."""


def formula_risk(value: object) -> bool:
    """Whether a spreadsheet would run ``value`` as a formula.

    Parameters
    ----------
    value : object
        A cell or a column name.

    Returns
    -------
    bool
        True when ``value`` is a string whose first character is in
        :data:`FORMULA_TRIGGERS`.

    References
    ----------
    OWASP, "CSV Injection", https://owasp.org/www-community/attacks/CSV_Injection.

    Examples
    --------
    >>> formula_risk("=1+1"), formula_risk("gyro_x"), formula_risk(-1.5)
    (True, False, False)
    """
    return isinstance(value, str) and value[:1] in FORMULA_TRIGGERS


def neutralise_cell(value: object) -> object:
    """A cell made safe for a spreadsheet: a ``'`` in front when :func:`formula_risk`.

    OWASP's mitigation: the spreadsheet shows the text, the apostrophe is its "text"
    marker.  For tables meant for spreadsheets only: a program reading the file sees the
    apostrophe.

    Parameters
    ----------
    value : object
        A cell.

    Returns
    -------
    object
        ``"'" + value`` for a risky string; anything else, numbers included, unchanged.

    Examples
    --------
    >>> neutralise_cell("@SUM(A1)"), neutralise_cell(3.0)
    ("'@SUM(A1)", 3.0)
    """
    return "'" + value if isinstance(value, str) and formula_risk(value) else value


def warn_formula_names(path: str | Path, names: Iterable[str], what: str = "column") -> None:
    """Warn when a CSV output will hold a name a spreadsheet would run as a formula.

    The name is written as it is, since a program reading the file must find it again, but
    a spreadsheet opening the CSV would run it (OWASP "CSV Injection").

    Parameters
    ----------
    path : str or pathlib.Path
        The output; only a CSV (``.csv``, or ``.csv.gz`` unpacked into one) is concerned.
    names : iterable of str
        The column (or other) names written into it.
    what : str
        How the warning names them (``"column"``).

    Warns
    -----
    ThermocalWarning
        One of ``names`` begins with a character of :data:`FORMULA_TRIGGERS`.
    """
    import warnings

    from thermocal.errors import ThermocalWarning

    if not Path(path).name.lower().endswith((".csv", ".csv.gz")):
        return
    risky = [n for n in names if formula_risk(n)]
    if risky:
        more = f" (and {len(risky) - 1} more)" if len(risky) > 1 else ""
        warnings.warn(
            f"{path}: {what} {risky[0]!r}{more} begins with {risky[0][0]!r}: a spreadsheet "
            'opening this CSV runs it as a formula (OWASP "CSV Injection"); kept as it is '
            "for programs reading the file: rename it before opening the CSV in a spreadsheet, "
            "or write Parquet",
            ThermocalWarning,
            stacklevel=2,
        )


__all__ = [
    "FORMULA_TRIGGERS",
    "SPECIAL_ROOTS",
    "check_outputs",
    "formula_risk",
    "neutralise_cell",
    "refuse_special",
    "refuse_special_input",
    "special_mode",
    "special_reason",
    "warn_formula_names",
]


def sidecar_path(path: str | Path) -> Path:
    """The metadata sidecar of a recording: ``FILE.meta.json`` beside ``FILE``.

    Parameters
    ----------
    path : str or pathlib.Path
        The recording.

    Returns
    -------
    pathlib.Path
        The sidecar's path (it may not exist).

    Examples
    --------
    >>> sidecar_path("runs/a.csv").as_posix()
    'runs/a.csv.meta.json'
    """
    p = Path(path)
    return p.with_name(p.name + ".meta.json")


TEMP_SUFFIX = ".thermocal-partial"
"""Suffix of an output being written.  No reader accepts it (:func:`file_kind`), so an
interrupted write can never be mistaken for a result; the next run that writes the same
output removes the stale ones (:func:`remove_stale_temporaries`)."""
