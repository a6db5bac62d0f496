"""Compile and run generated C against Python (tests, float error; :mod:`thermocal.export.c`)."""

from __future__ import annotations

import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from thermocal.errors import ThermocalInputError
from thermocal.export.c.core import REAL_TYPES, CExport, generate_c
from thermocal.recording import FloatArray

# --- compile and run (tests, float error) -----------------------------------------------------


def c_harness(export: CExport) -> str:
    """A small C main: reads ``n`` then ``n`` records of doubles ``(t, T_1..T_k, F)`` from
    a binary file (argv[1]), calls ``init(τ = argv[3])`` and ``update`` on each sample and
    writes the model values as doubles to argv[2].

    Parameters
    ----------
    export : CExport
        The generated module the harness calls.

    Returns
    -------
    str
        C99 source of ``main`` (argv: input, output, sample interval [s], optional known
        input [signal unit]).
    """
    p, P, r = export.prefix, export.prefix.upper(), f"{export.prefix}_real"
    return f"""#include <stdio.h>
#include <stdlib.h>
#include "{p}.h"

int main(int argc, char **argv)
{{
    FILE *in, *out;
    long n, i;
    double rec[{P}_N_TEMPS + 2];
    {r} temps[{P}_N_TEMPS];
    {p}_state st;
    int j;
    if (argc < 4) {{
        return 2;
    }}
    in = fopen(argv[1], "rb");
    out = fopen(argv[2], "wb");
    if (in == NULL || out == NULL) {{
        return 2;
    }}
    if (fread(&n, sizeof n, 1, in) != 1) {{
        return 2;
    }}
    {p}_init(&st, atof(argv[3]));
    if (argc > 4) {{
        {p}_set_known_input(&st, ({r})atof(argv[4]));
    }}
    for (i = 0; i < n; ++i) {{
        double y;
        if (fread(rec, sizeof(double), {P}_N_TEMPS + 2, in) != {P}_N_TEMPS + 2) {{
            return 3;
        }}
        for (j = 0; j < {P}_N_TEMPS; ++j) {{
            temps[j] = ({r})rec[1 + j];
        }}
        y = (double){p}_update(&st, rec[0], temps, ({r})rec[{P}_N_TEMPS + 1]);
        fwrite(&y, sizeof y, 1, out);
    }}
    fclose(in);
    fclose(out);
    return 0;
}}
"""


CFLAGS = ("-O2", "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic")


def find_compiler() -> str | None:
    """The system C compiler (``cc``, ``gcc`` or ``clang``), or None."""
    for name in ("cc", "gcc", "clang"):
        path = shutil.which(name)
        if path:
            return path
    return None


def compile_harness(export: CExport, directory: str | Path, compiler: str | None = None) -> Path:
    """Write the module and :func:`c_harness` into ``directory`` and compile them with
    ``cc -O2 -std=c99 -Wall -Wextra -Werror -pedantic``; returns the executable.

    Parameters
    ----------
    export : CExport
        The generated module.
    directory : str or Path
        Where the sources and the executable are written.
    compiler : str or None, optional
        The C compiler; default ``None``: :func:`find_compiler`.

    Returns
    -------
    Path
        The compiled executable.

    Raises
    ------
    ThermocalInputError
        When no C compiler is found.
    RuntimeError
        When compilation fails (a defect of the generated code; stderr in the message).
    """
    cc = compiler or find_compiler()
    if cc is None:
        raise ThermocalInputError("no C compiler (cc, gcc or clang) found")
    d = Path(directory)
    export.write(d)
    main = d / f"{export.prefix}_main.c"
    main.write_text(c_harness(export))
    exe = d / f"{export.prefix}_run"
    cmd = [cc, *CFLAGS, "-o", str(exe), str(d / export.source_name), str(main), "-lm"]
    proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if proc.returncode != 0:
        raise RuntimeError(f"C compilation failed: {' '.join(cmd)}\n{proc.stderr}")
    return exe


def run_harness(
    exe: str | Path,
    time_s: npt.ArrayLike,
    temps_c: npt.ArrayLike,
    signal: npt.ArrayLike,
    sample_interval_s: float,
    *,
    known_input: float = 0.0,
) -> FloatArray:
    """Run a compiled harness on samples; returns the model values (n,).

    Parameters
    ----------
    exe : str or Path
        Executable of :func:`compile_harness`.
    time_s : array_like, shape (n,)
        Sample times [s].
    temps_c : array_like, shape (n, k)
        Temperatures [°C] (or the model's temperature unit), one column per model input.
    signal : array_like, shape (n,)
        The measured signal [signal unit of the export].
    sample_interval_s : float
        Interval given to ``<p>_init`` [s].
    known_input : float, optional
        Known input removed by the module [signal unit] (default 0.0).

    Returns
    -------
    numpy.ndarray, shape (n,)
        The values ``<p>_update`` returns [signal unit].

    Raises
    ------
    RuntimeError
        When the harness exits with a non-zero status.
    """
    t = np.asarray(time_s, dtype=np.float64)
    T = np.asarray(temps_c, dtype=np.float64).reshape(t.size, -1)
    f = np.asarray(signal, dtype=np.float64)
    rec = np.column_stack([t, T, f])
    with tempfile.TemporaryDirectory() as tmp:
        fin = Path(tmp) / "in.bin"
        fout = Path(tmp) / "out.bin"
        with open(fin, "wb") as fh:
            fh.write(np.int64(t.size).tobytes())
            fh.write(np.ascontiguousarray(rec).tobytes())
        proc = subprocess.run(
            [
                str(exe),
                str(fin),
                str(fout),
                repr(float(sample_interval_s)),
                repr(float(known_input)),
            ],
            capture_output=True,
            check=False,
        )
        if proc.returncode != 0:
            raise RuntimeError(f"C harness failed with status {proc.returncode}")
        return np.fromfile(fout, dtype=np.float64)


def exercise_inputs(
    model: dict[str, Any],
    n: int = 100_000,
    sample_interval_s: float = 1.0,
    seed: int = 0,
    *,
    gap_at: float = 0.6,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Synthetic samples over a model's fitted range, power-on included: every
    temperature channel sweeps its fitted range ±10 % (triangle waves of different
    periods, so rates and clamping occur), a gap of 7 τ after the fraction ``gap_at``
    of the samples, signal = small noise.

    Parameters
    ----------
    model : dict
        A model dict (its ``temperatures`` and ``range.temperature_c``).
    n : int, optional
        Number of samples (default 100 000).
    sample_interval_s : float, optional
        Sample interval [s] (default 1.0).
    seed : int, optional
        Seed of ``numpy.random.default_rng`` (default 0).
    gap_at : float, optional
        Fraction of the samples after which the 7-interval gap falls (default 0.6).

    Returns
    -------
    time_s : numpy.ndarray, shape (n,)
        Sample times [s].
    temps_c : numpy.ndarray, shape (n, k)
        Temperatures [°C]: each a triangle wave over its range widened by 10 % each side.
    signal : numpy.ndarray, shape (n,)
        Gaussian noise of standard deviation 0.01 [signal unit].

    Examples
    --------
    >>> m = {"temperatures": ["T1"], "range": {"temperature_c": {"T1": [10.0, 40.0]}}}
    >>> t, T, f = exercise_inputs(m, n=1000)
    >>> T.shape, round(float(T.min()), 1), round(float(T.max()), 1), float(t[-1])
    ((1000, 1), 7.0, 43.0, 1006.0)
    """
    rng = np.random.default_rng(seed)
    t = np.arange(n, dtype=np.float64) * sample_interval_s
    t[int(gap_at * n) :] += 7.0 * sample_interval_s
    tr = model["range"]["temperature_c"]
    names = model["temperatures"]
    cols = []
    for i, name in enumerate(names):
        lo, hi = (float(v) for v in tr[name])
        span = max(hi - lo, 1e-3)
        period = (n * sample_interval_s) / (3.0 + 1.7 * i)
        phase = (t / period + 0.13 * i) % 1.0
        tri = 1.0 - np.abs(2.0 * phase - 1.0)
        cols.append(lo - 0.1 * span + 1.2 * span * tri + 0.001 * span * rng.standard_normal(n))
    sig = 0.01 * rng.standard_normal(n)
    return t, np.column_stack(cols), sig


@dataclass(frozen=True)
class FloatError:
    """Worst-case difference of the float build from the double build on :func:`exercise_inputs`:
    ``max_abs`` [signal unit], ``max_rel`` (relative to max |ŷ|), ``n_samples``.

    Attributes
    ----------
    max_abs : float
        Largest |float − double| [signal unit].
    max_rel : float
        ``max_abs`` relative to max |ŷ|.
    n_samples : int
        Number of samples compared.
    """

    max_abs: float
    max_rel: float
    n_samples: int


def measure_float_error(
    model: dict[str, Any],
    *,
    prefix: str = "thermocal_model",
    n: int = 100_000,
    sample_interval_s: float = 1.0,
    compiler: str | None = None,
    unit: str | None = None,
) -> FloatError:
    r"""Compile the double and float builds and compare them on the same inputs.

    Parameters
    ----------
    model : dict
        A model dict (:func:`thermocal.pipeline.model_file.load_model_dict`).
    prefix : str, optional
        C prefix (default ``"thermocal_model"``).
    n : int, optional
        Number of samples of :func:`exercise_inputs` (default 100 000).
    sample_interval_s : float, optional
        Sample interval [s] (default 1.0).
    compiler : str or None, optional
        The C compiler; default ``None``: :func:`find_compiler`.
    unit : str or None, optional
        Signal unit of the generated functions (default: the unit fitted on).

    Returns
    -------
    FloatError
        The largest absolute and relative differences.

    Raises
    ------
    ThermocalInputError
        When no C compiler is found or the model cannot be exported.

    Notes
    -----
    .. math:: e_\mathrm{abs} = \max_k |\hat y^{f}_k - \hat y^{d}_k|,\quad
              e_\mathrm{rel} = e_\mathrm{abs} / \max_k |\hat y^{d}_k|

    with :math:`\hat y^{f}`, :math:`\hat y^{d}` the float and double builds' outputs.
    """
    t, T, f = exercise_inputs(model, n, sample_interval_s)
    outs = []
    with tempfile.TemporaryDirectory() as tmp:
        for real in REAL_TYPES:
            ex = generate_c(
                model, prefix=prefix, real=real, sample_interval_s=sample_interval_s, unit=unit
            )
            exe = compile_harness(ex, Path(tmp) / real, compiler)
            outs.append(run_harness(exe, t, T, f, sample_interval_s))
    d = np.abs(outs[1] - outs[0])
    scale = float(np.max(np.abs(outs[0]))) or 1.0
    return FloatError(float(d.max()), float(d.max()) / scale, int(t.size))
