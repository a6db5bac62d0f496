"""The warm-up model's fit maths ([Seed-Plan]): each run's start values and post-window
changes, the count of distinct start temperatures, and the two ways of solving for the
coefficients in scaled variables (stage 1 per run then stage 2 across runs, or both in one
least-squares problem), with the model's evaluation ``ΔF = Σ_j a_j(T0) ΔT^j``.

Pure functions on arrays; :class:`thermocal.models.warmup.WarmupModel` strings them
together and turns the scaled coefficients into the physical b matrix.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np

from thermocal.errors import DesignError
from thermocal.models.numerics import _window_count, horner, lstsq_svd, running_start_mean
from thermocal.models.rundata import RunData
from thermocal.recording import FloatArray

DISTINCT_T0_C = 1.0
"""Start temperatures closer than this [°C] count as one start temperature."""


@dataclasses.dataclass(frozen=True)
class ScaledFit:
    """The warm-up fit in scaled variables (``w = ΔT/s``, ``u = (T0 − μ)/σ``).

    Attributes
    ----------
    c_scaled : numpy.ndarray
        Coefficients c (n_j × n_k) of ``w^j u^k``.
    cov_c : numpy.ndarray or None
        Covariance of ``vec c`` (None without residual degrees of freedom).
    dof : int
        Residual degrees of freedom.
    cond : float
        Worst 2-norm condition number of the designs.
    run_coefs : numpy.ndarray or None
        The per-run stage-1 coefficients (two-stage only).
    """

    c_scaled: FloatArray
    cov_c: FloatArray | None
    dof: int
    cond: float
    run_coefs: FloatArray | None


def term_name(j: int, k: int) -> str:
    """The name of coefficient ``b_jk`` with its term (``"b21 (ΔT^2·T0^1)"``).

    Parameters
    ----------
    j, k : int
        Powers of ΔT and of T0.

    Returns
    -------
    str
    """
    return f"b{j}{k} (ΔT^{j}·T0^{k})"


def evaluate(b: FloatArray, t0: FloatArray, dt: FloatArray) -> FloatArray:
    """The warm-up model's change of output since the start window.

    Parameters
    ----------
    b : numpy.ndarray
        The b matrix, shape (order + 1, t0_order + 1) [signal unit / °C^(j+k)].
    t0 : numpy.ndarray
        Start temperature T0 of each sample [°C].
    dt : numpy.ndarray
        ΔT = T − T0 of each sample [°C].

    Returns
    -------
    numpy.ndarray
        ΔF [signal unit].

    Notes
    -----
    .. math:: \\Delta F = \\sum_j a_j(T_0)\\,\\Delta T^j, \\qquad
              a_j(T_0) = \\sum_k b_{jk} T_0^k

    evaluated by Horner's rule in both.
    """
    a = [horner(b[j], t0) for j in range(b.shape[0])]
    out = a[-1]
    for aj in a[-2::-1]:
        out = out * dt + aj
    return out


def start_values(
    one: list[RunData], *, order: int, j0: int, start_window_s: float
) -> tuple[list[float], list[float], list[FloatArray], list[FloatArray]]:
    """Per run: T0 and F0 (means over the start window) and the post-window ΔT, ΔF.

    Parameters
    ----------
    one : list of RunData
        Runs with one temperature channel.
    order : int
        Highest power of ΔT.
    j0 : int
        Lowest power of ΔT (0 with the constant a_0, else 1).
    start_window_s : float
        Start window [s].

    Returns
    -------
    tuple of lists
        T0 [°C], F0 [signal unit], ΔT [°C] and ΔF [signal unit] per run.

    Raises
    ------
    thermocal.errors.DesignError
        A run with fewer post-window samples than coefficients.
    """
    n_j = int(order) + 1 - j0
    t0s, f0s, dts, dfs = [], [], [], []
    for r in one:
        temp = r.temps_c[:, 0]
        y = r.target()
        m = _window_count(r.time_s, start_window_s)
        t0 = float(running_start_mean(r.time_s, temp, start_window_s)[-1])
        f0 = float(running_start_mean(r.time_s, y, start_window_s)[-1])
        if r.n_samples - m < n_j:
            raise DesignError(
                f"warmup: {r.name or 'run'} has {r.n_samples - m} samples after the "
                f"{start_window_s:g} s start window; at least {n_j} are needed "
                f"(order {order})"
            )
        t0s.append(t0)
        f0s.append(f0)
        dts.append(temp[m:] - t0)
        dfs.append(y[m:] - f0)
    return t0s, f0s, dts, dfs


def distinct_start_temperatures(t0_arr: FloatArray, t0_order: int) -> int:
    """How many start temperatures at least :data:`DISTINCT_T0_C` apart (greedy on the
    sorted T0s).

    Parameters
    ----------
    t0_arr : numpy.ndarray
        Start temperatures [°C].
    t0_order : int
        Highest power of T0.

    Returns
    -------
    int

    Raises
    ------
    thermocal.errors.DesignError
        Fewer than ``t0_order + 1``.
    """
    kt = int(t0_order)
    srt = np.sort(t0_arr)
    n_distinct = 1 + int(np.count_nonzero(np.diff(srt) >= DISTINCT_T0_C))
    if n_distinct < kt + 1:
        raise DesignError.naming(
            f"warmup: t0_order={kt} needs runs at ≥ {kt + 1} distinct start temperatures "
            f"(≥ {DISTINCT_T0_C:g} °C apart); got {n_distinct} "
            f"({', '.join(f'{v:.2f}' for v in srt)} °C); add runs or lower {{t0_order}}",
            "t0_order",
        )
    return n_distinct


def fit_two_stage(
    one: list[RunData],
    dts: list[FloatArray],
    dfs: list[FloatArray],
    t0_arr: FloatArray,
    scales: tuple[float, float, float],
    *,
    order: int,
    t0_order: int,
    j0: int,
) -> ScaledFit:
    """Stage 1 per run (``ΔF = Σ_j a_j ΔT^j``), stage 2 across runs (``a_j = Σ_k c_jk u^k``),
    in the scaled variables.

    Parameters
    ----------
    one : list of RunData
        The runs (for the messages).
    dts, dfs : list of numpy.ndarray
        Post-window ΔT [°C] and ΔF [signal unit] per run.
    t0_arr : numpy.ndarray
        Start temperatures [°C].
    scales : tuple of float
        ``(s, μ, σ)``: ``w = ΔT/s``, ``u = (T0 − μ)/σ`` [°C].
    order, t0_order, j0 : int
        Powers of ΔT (``j0``…``order``) and of T0 (0…``t0_order``).

    Returns
    -------
    ScaledFit

    Raises
    ------
    thermocal.errors.DesignError
        A term the data cannot determine.
    """
    s_dt, mu, sig = scales
    kt = int(t0_order)
    n_j, n_k = order + 1 - j0, kt + 1
    powers_j = np.arange(j0, order + 1)
    a_runs = np.empty((len(one), n_j))
    cond = 0.0
    for i, (dt, df) in enumerate(zip(dts, dfs, strict=True)):
        x = (dt / s_dt)[:, None] ** powers_j[None, :]
        res = lstsq_svd(x, df)
        if res.rank < n_j:
            terms = ", ".join(f"ΔT^{powers_j[c]}" for c in res.null_columns)
            raise DesignError(
                f"warmup: {one[i].name or f'run {i}'}: term(s) {terms} cannot be "
                f"determined (ΔT takes too few distinct values after the start window)"
            )
        cond = max(cond, res.condition_number)
        a_runs[i] = res.coef
    v = (t0_arr - mu) / sig
    vmat = v[:, None] ** np.arange(n_k)[None, :]
    res2 = lstsq_svd(vmat, a_runs)
    if res2.rank < n_k:
        raise DesignError.naming(
            f"warmup: the start temperatures cannot determine T0 terms up to "
            f"T0^{kt}; lower {{t0_order}}",
            "t0_order",
        )
    cond = max(cond, res2.condition_number)
    c_scaled = res2.coef.T  # (n_j, n_k)
    # cov(vec c) block-diagonal over j (per-coefficient residual variance)
    cov_c: FloatArray | None = (
        np.asarray(np.kron(np.diag(res2.sigma2), res2.cov_unit), dtype=np.float64)
        if res2.dof > 0
        else None
    )
    dof = res2.dof
    run_coefs: FloatArray | None = a_runs
    return ScaledFit(c_scaled, cov_c, int(dof), float(cond), run_coefs)


def fit_joint(
    one: list[RunData],
    dts: list[FloatArray],
    dfs: list[FloatArray],
    t0s: Sequence[float],
    scales: tuple[float, float, float],
    *,
    order: int,
    t0_order: int,
    j0: int,
    per_run_offset: bool,
) -> ScaledFit:
    """Both stages in one least-squares problem, in the scaled variables (per-run a_0 as
    nuisance parameters when ``per_run_offset``).

    Parameters
    ----------
    one : list of RunData
        The runs (for the messages).
    dts, dfs : list of numpy.ndarray
        Post-window ΔT [°C] and ΔF [signal unit] per run.
    t0s : sequence of float
        Start temperatures [°C].
    scales : tuple of float
        ``(s, μ, σ)``: ``w = ΔT/s``, ``u = (T0 − μ)/σ`` [°C].
    order, t0_order, j0 : int
        Powers of ΔT (``j0``…``order``) and of T0 (0…``t0_order``).
    per_run_offset : bool
        A turn-on offset per run.

    Returns
    -------
    ScaledFit

    Raises
    ------
    thermocal.errors.DesignError
        A singular design.
    """
    s_dt, mu, sig = scales
    t0_arr = np.asarray(t0s, dtype=np.float64)
    all_dt = np.concatenate(dts)
    kt = int(t0_order)
    n_j, n_k = order + 1 - j0, kt + 1
    powers_j = np.arange(j0, order + 1)
    u = np.concatenate([np.full(dt.size, (t0 - mu) / sig) for dt, t0 in zip(dts, t0s, strict=True)])
    w = all_dt / s_dt
    offsets = bool(per_run_offset) and j0 == 0
    slope_j = powers_j[1:] if offsets else powers_j
    cols = [w**j * u**k for j in slope_j for k in range(n_k)]
    labels = [term_name(int(j), k) for j in slope_j for k in range(n_k)]
    if offsets:
        # per-run a0 as nuisance parameters (turn-on F0 noise stays out of the slopes)
        run_id = np.concatenate([np.full(dt.size, i) for i, dt in enumerate(dts)])
        ind = [(run_id == i).astype(np.float64) for i in range(len(dts))]
        cols = ind + cols
        run_labels = [f"a0 of {r.name or f'run {i}'}" for i, r in enumerate(one)]
        labels = run_labels + labels
    x = np.column_stack(cols)
    res = lstsq_svd(x, np.concatenate(dfs))
    if res.rank < x.shape[1]:
        bad = ", ".join(labels[c] for c in res.null_columns)
        raise DesignError(f"warmup: singular joint design; term(s) {bad}")
    cond = res.condition_number
    dof = res.dof
    if offsets:
        n_r = len(dts)
        cov_all = res.sigma2 * res.cov_unit if res.dof > 0 else None
        # a0(T0) = Σ_k b_0k T0^k fitted to the per-run offsets (as in stage 2)
        v = (t0_arr - mu) / sig
        vmat = v[:, None] ** np.arange(n_k)[None, :]
        res0 = lstsq_svd(vmat, res.coef[:n_r])
        if res0.rank < n_k:
            raise DesignError.naming(
                f"warmup: the start temperatures cannot determine T0 terms up to "
                f"T0^{kt}; lower {{t0_order}}",
                "t0_order",
            )
        cond = max(cond, res0.condition_number)
        c_scaled = np.vstack([res0.coef[None, :], res.coef[n_r:].reshape(-1, n_k)])
        if cov_all is not None and res0.dof > 0:
            cov_c = np.zeros((n_j * n_k, n_j * n_k))
            cov_c[:n_k, :n_k] = float(res0.sigma2) * res0.cov_unit
            cov_c[n_k:, n_k:] = cov_all[n_r:, n_r:]
        else:
            cov_c = None
    else:
        c_scaled = res.coef.reshape(n_j, n_k)
        cov_c = res.sigma2 * res.cov_unit if res.dof > 0 else None
    run_coefs = None
    return ScaledFit(c_scaled, cov_c, int(dof), float(cond), run_coefs)
