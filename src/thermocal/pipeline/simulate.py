"""Simulated recordings written to files: the ``simulate`` command as one library call.

:func:`simulate_files` runs a scenario (:func:`thermocal.simulate.simulate_scenario`),
names its files (:func:`simulation_paths`), refuses outputs over the inputs or on special
files before and after simulating (:func:`thermocal.outputs.check_outputs`), writes each
recording (a CSV with its ``.meta.json`` sidecar) and the truth JSON, and returns a
:class:`SimulatedFiles` whose :meth:`~SimulatedFiles.to_dict` is what the command prints as
JSON.

Output naming:

* one recording: a data file name (``run.csv``, ``run.parquet``) is that file;
* several: a directory (no data extension) gets ``<scenario>_<label>.csv`` (or ``.parquet``
  with ``file_format="parquet"``); a data file name is a stem: ``out/warm.csv`` gives
  ``out/warm_T+25.csv`` ….
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from thermocal import defaults
from thermocal.errors import FileFormatError, ParameterError, ThermocalInputError
from thermocal.outputs import check_outputs, sidecar_path
from thermocal.readers import file_kind
from thermocal.readers.formats import file_suffix, format_named
from thermocal.readers.program import read_program
from thermocal.simulate import SimulateOptions, Simulation, simulate_scenario
from thermocal.writers import (
    RECORDING_WRITERS,
    check_not_input,
    write_json,
    write_recording,
    written_format,
)


def check_scenario(scenario: str) -> None:
    """Refuse a scenario name that is not one of :data:`thermocal.defaults.SCENARIO_NAMES`.

    Parameters
    ----------
    scenario : str
        The scenario's name.

    Raises
    ------
    ThermocalInputError
        An unknown name (the message lists the known ones).
    """
    if scenario not in defaults.SCENARIO_NAMES:
        raise ThermocalInputError(
            f"unknown scenario {scenario!r}; known scenarios: {', '.join(defaults.SCENARIO_NAMES)}"
        )


def _is_data_file(path: Path) -> bool:
    """Whether ``path`` names a data file (a known extension) rather than a directory."""
    try:
        file_kind(path)
    except FileFormatError:
        return False
    return True


def simulation_paths(
    output: Path, scenario: str, labels: Sequence[str], file_format: str = "csv"
) -> list[Path]:
    """The file each recording of a scenario is written to.

    Parameters
    ----------
    output : pathlib.Path
        A data file (one recording: that file; several: a stem) or a directory.
    scenario : str
        The scenario's name (the directory's file names begin with it).
    labels : sequence of str
        One label per recording (:attr:`thermocal.simulate.Simulation.labels`).
    file_format : str
        ``"csv"`` or ``"parquet"``: the format inside a directory.

    Returns
    -------
    list of pathlib.Path
        One path per label.

    Raises
    ------
    ParameterError
        ``file_format`` not csv or parquet (with a directory).
    ThermocalInputError
        ``output`` exists and is neither a data file name nor a directory.

    Examples
    --------
    >>> [p.as_posix() for p in simulation_paths(Path("out/warm.csv"), "x", ["T+0", "T+20"])]
    ['out/warm_T+0.csv', 'out/warm_T+20.csv']
    >>> simulation_paths(Path("out"), "fog-slow", [""], "parquet")[0].as_posix()
    'out/fog-slow.parquet'
    """
    if _is_data_file(output):
        if len(labels) == 1:
            return [output]
        suffix = file_suffix(output)  # the registered one: out.csv.gz → out_T+0.csv.gz
        stem = output.name[: -len(suffix)]
        return [output.with_name(f"{stem}_{lab}{suffix}") for lab in labels]
    if file_format not in RECORDING_WRITERS:
        raise ParameterError("file_format", f"{{name}} must be csv or parquet, got {file_format!r}")
    ext = format_named(file_format).suffixes[0]
    if output.exists() and not output.is_dir():
        raise ThermocalInputError(f"{output}: exists and is not a directory")
    return [output / (f"{scenario}_{lab}{ext}" if lab else f"{scenario}{ext}") for lab in labels]


def _early_gate(output: Path, truth: Path | None, inputs: list[str | Path]) -> None:
    """Refuse outputs over the inputs or on special files before simulating (the files
    named after the results are checked again once known)."""
    files, dirs = ([output], []) if _is_data_file(output) else ([], [output])
    if files:
        written_format(output)  # a format thermocal reads but does not write: refused now
    check_outputs([*files, *([truth] if truth is not None else [])], inputs, dirs=dirs)


@dataclass(frozen=True, eq=False)
class SimulatedFiles:
    """What :func:`simulate_files` wrote.

    Attributes
    ----------
    simulation : thermocal.simulate.Simulation
        The recordings and their truth.
    paths : tuple of pathlib.Path
        The file of each recording.
    truth : pathlib.Path or None
        The truth JSON, when written.
    """

    simulation: Simulation
    paths: tuple[Path, ...]
    truth: Path | None

    def to_dict(self) -> dict[str, Any]:
        """The summary the ``simulate`` command prints as JSON.

        Returns
        -------
        dict
            ``scenario``, ``seed``, ``files`` (paths as text), ``n_samples`` (one per file)
            and ``truth`` (the truth JSON's path, or None).
        """
        sim = self.simulation
        return {
            "scenario": sim.scenario,
            "seed": sim.seed,
            "files": [str(p) for p in self.paths],
            "n_samples": [rec.n_samples for rec, _ in sim.results],
            "truth": str(self.truth) if self.truth is not None else None,
        }


def simulate_files(
    scenario: str,
    output: Path,
    *,
    seed: int = 0,
    profile: Path | None = None,
    truth: Path | None = None,
    options: SimulateOptions | None = None,
    file_format: str = "csv",
) -> SimulatedFiles:
    """Simulate a scenario and write its recordings (and truth) to files.

    Parameters
    ----------
    scenario : str
        A scenario of :data:`thermocal.simulate.SCENARIOS`.
    output : pathlib.Path
        A data file, a stem or a directory (:func:`simulation_paths`).
    seed : int
        The seed: the same seed gives the same files.
    profile : pathlib.Path, optional
        A chamber program CSV (``time_s``, ``setpoint_c``) run instead of the scenario's.
    truth : pathlib.Path, optional
        Where to write every true parameter (JSON).
    options : thermocal.simulate.SimulateOptions, optional
        The scenario's options (default: its own).
    file_format : str
        ``"csv"`` or ``"parquet"`` inside an output directory.

    Returns
    -------
    SimulatedFiles

    Raises
    ------
    ThermocalInputError
        An unknown scenario, an option it does not take, an output over an input.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     run = simulate_files("turntable-16", Path(d) / "tt.csv", seed=0)
    ...     run.to_dict()["n_samples"][0] > 0
    True
    """
    check_scenario(scenario)
    inputs: list[str | Path] = [profile] if profile is not None else []
    _early_gate(output, truth, inputs)
    prog = read_program(profile) if profile is not None else None
    sim = simulate_scenario(scenario, seed, prog, options or SimulateOptions())
    paths = simulation_paths(output, scenario, list(sim.labels), file_format)
    sidecars = [sidecar_path(p) for p in paths if file_kind(p) == "csv"]
    check_outputs([*paths, *sidecars], inputs, dirs=[p.parent for p in paths])
    if truth is not None:
        check_not_input(truth, [*inputs, *paths])
    for (rec, _), p in zip(sim.results, paths, strict=True):
        write_recording(rec, p)
    if truth is not None:
        profile_name = str(profile) if profile is not None else None
        write_json(truth, sim.truth_document([str(p) for p in paths], profile_name))
    return SimulatedFiles(sim, tuple(paths), truth)


__all__ = [
    "SimulatedFiles",
    "check_scenario",
    "simulate_files",
    "simulation_paths",
]
