"""Warm-up (self-heating) model with start-temperature dependence ([Seed-Plan]).

For a sensor used minutes after power-on.  Each run is one power-on.  With
``T`` the temperature of one channel [°C] and ``F`` the output (known input
removed) [signal unit]:

* ``T0``, ``F0`` — the means of the samples of the start window (the first
  ``start_window_s`` seconds: samples with ``t − t_first < start_window_s``);
* ``ΔT = T − T0``, ``ΔF = F − F0`` for every later sample and, per run (stage 1)::

      ΔF = a0 + a1 ΔT + a2 ΔT² + … + a_N ΔT^N          (N = ``order``)

* each coefficient is a polynomial in the start temperature (stage 2, over the
  l runs)::

      a_j(T0) = b_j0 + b_j1 T0 + … + b_jM T0^M          (M = ``t0_order``)

In use (``predict``/``stream``): measure T0 at power-on, evaluate ``a_j(T0)``,
compute ``ΔT = T − T0`` at every sample and return ``ΔF``; the corrected output
is ``F' = F − ΔF``.  Causality: during the start window T0 is the running mean
of the samples so far (``T0_i = (1/(i+1)) Σ_{k≤i} T_k``), frozen once the window
is full (first sample with ``t − t_first ≥ start_window_s``); predict and stream
do exactly this, so they agree to the last bit.  A gap in time does not restart
the window (the window is measured in time from the first sample; only
``ModelStream.reset()`` — a new power-on — does).

Fitting (least squares, SVD; our reading of [Seed-Plan]): ΔT is scaled by its largest
absolute value and T0 centred and scaled, the solution is then converted back
to the physical ``b``.  ``method="two_stage"`` is the seed's procedure (a_j per
run, then a_j against T0); ``method="joint"`` fits ``ΔF = Σ_j Σ_k b_jk T0^k ΔT^j``
to all samples of all runs at once (same model, one least-squares problem).
Stage 2 needs runs at ≥ ``t0_order + 1`` distinct start temperatures (start
temperatures closer than :data:`~thermocal.models.warmup_fit.DISTINCT_T0_C` count as one), otherwise
:class:`~thermocal.errors.DesignError`.

Out of range: the temperature is clamped to the channel's fitted range and T0 to
the fitted start-temperature range, each with an
:class:`~thermocal.errors.ExtrapolationWarning` (``extrapolate=True`` evaluates
as is, still warning).  ΔT is not clamped separately.

Learned state (``_state()``, the layout the C export reads)::

    {
      "b": [[b_00, …, b_0M], …, [b_N0, …, b_NM]],  # (order+1) × (t0_order+1), physical
                                                  # units [unit/°C^(j+k)]; row j is the
                                                  # ΔT^j coefficient, column k the T0^k
                                                  # power; row 0 all zero when a0 is off
      "order": N, "t0_order": M,
      "start_window_s": W,                        # start window [s]
      "sensor_name": "T1",                        # the temperature channel used
      "b_stderr": [[...]] or null,                # standard errors of b, same shape
      "t0_range_c": [lo, hi],                     # fitted start temperatures [°C]; T0 is
                                                  # clamped to it (T to the file's "range")
      "start_temps_c": [...], "start_outputs": [...],   # T0, F0 of each fitted run
      "run_coefficients": [[a_0, …, a_N], …]      # stage-1 a_j per run (two_stage)
    }

Evaluation (firmware twin), per sample: ``Tc = clamp(T, range)``; while
``t − t_first < start_window_s``: ``sum += Tc; n += 1``; ``T0 = sum/n`` (frozen
afterwards); ``a_j = Σ_k b_jk clamp(T0, t0_range_c)^k`` (Horner in T0);
``ΔF = Σ_j a_j (Tc − T0)^j`` (Horner in ΔT).

This module holds the estimator, :class:`WarmupModel`; the fit maths (start values, the
two-stage and joint solutions in scaled variables, the evaluation) are in
:mod:`thermocal.models.warmup_fit`, the streaming twin (:class:`WarmupStream`) in
:mod:`thermocal.models.warmup_stream`.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from typing import Any, ClassVar, Self

import numpy as np
import numpy.typing as npt

from thermocal.adequacy import Needs
from thermocal.errors import (
    ConditioningWarning,
    DesignError,
    ExtrapolationWarning,
    ModelFileError,
    ThermocalInputError,
)
from thermocal.families import WARMUP, FamilyDeclaration
from thermocal.models.base import ChunkContext, ModelStream, TemperatureModel
from thermocal.models.checks import (
    fields,
    integer,
    interval,
    key_path,
    matrix,
    number,
    sensor_param,
    string,
)
from thermocal.models.numerics import (
    _clamp_range,
    _poly_shift_matrix,
    _window_count,
    channel_index,
    horner,
    running_start_mean,
    single_channel,
)
from thermocal.models.results import Coefficient, FitStats
from thermocal.models.rundata import RunData
from thermocal.models.warmup_fit import (
    ScaledFit,
    distinct_start_temperatures,
    evaluate,
    fit_joint,
    fit_two_stage,
    start_values,
)
from thermocal.models.warmup_stream import WarmupStream
from thermocal.recording import FloatArray

CONDITION_WARN = 1e10
"""A scaled design with a 2-norm condition number above this gets a ConditioningWarning."""


METHODS = ("two_stage", "joint")


# --- the model ------------------------------------------------------------------------------


class WarmupModel(TemperatureModel):
    """Two-stage warm-up model ``ΔF = Σ_j a_j(T0) ΔT^j``, ``a_j(T0) = Σ_k b_jk T0^k``
    ([Seed-Plan]).

    Parameters
    ----------
    order : highest power N of ΔT (≥ 1).
    t0_order : highest power M of T0 in each a_j (≥ 0).
    start_window_s : start window [s] for T0 and F0 (the seed's first m samples).  Keep
        it short against the die's thermal time constant: T rising during the window
        biases T0 (on the simulator's mems-gyro, 10 s leaves 8 % of the drift, 0.5 s
        0.1 %, noise-free); long enough to average the noise of T.
    include_a0 : keep the constant a0 (the seed does); off forces ΔF = 0 at ΔT = 0.
    sensor : index of the temperature channel used (0 = first named channel).
    method : ``"two_stage"`` (seed) or ``"joint"`` (one least-squares problem).
    per_run_offset : ``joint`` only: a free a0 per run (nuisance parameters, so the
        noise of each run's F0 does not bias the ΔT terms), then ``a0(T0)`` fitted to
        those offsets as in stage 2.  (``two_stage`` always has a free a0 per run.)

    Notes
    -----
    With :math:`T_0` and :math:`F_0` the means of the first ``start_window_s`` seconds of a
    power-on and :math:`\\Delta T = T - T_0`, the drift of the output is

    .. math::

        \\Delta F = \\sum_{j=0}^{n} \\Bigl(\\sum_{k=0}^{m} b_{jk} T_0^k\\Bigr)
                   \\Delta T^j ,

    :math:`n` = ``order``, :math:`m` = ``t0_order``, fitted over several power-ons at
    different start temperatures.

    References
    ----------
    .. [1] *Temperature-characteristic calibration test plan* (a MEMS sensor's power-on
       warm-up tests and model; docs/methods.md, Seed-Plan).

    Examples
    --------
    >>> import numpy as np
    >>> from thermocal.models import RunData
    >>> from thermocal.models.warmup import WarmupModel
    >>> runs = []
    >>> for t0 in (10.0, 25.0, 40.0):
    ...     t = np.arange(0.0, 900.0, 1.0)
    ...     temp = t0 + 8.0 * (1.0 - np.exp(-t / 300.0))
    ...     drift = 0.1 + (0.02 + 0.001 * t0) * (temp - t0)
    ...     runs.append(RunData(t, temp[:, None], drift, ("T1",)))
    >>> model = WarmupModel(order=1, t0_order=1).fit(runs)
    >>> {c.name: round(c.value, 5) for c in model.coefficients()}["b11"]
    0.001
    >>> round(float(model.predict(runs[1])[-1]), 3)
    0.342
    """

    declaration: ClassVar[FamilyDeclaration] = WARMUP
    uses_rate: ClassVar[bool] = False

    b_: FloatArray
    b_stderr_: FloatArray | None
    t0_range_: tuple[float, float]
    duration_range_s_: tuple[float, float] | None
    sensor_name_: str
    start_temps_: FloatArray
    start_outputs_: FloatArray
    run_coefficients_: FloatArray | None

    def __init__(
        self,
        order: int = 2,
        t0_order: int = 2,
        start_window_s: float = 1.0,
        include_a0: bool = True,
        sensor: int = 0,
        method: str = "two_stage",
        per_run_offset: bool = True,
    ) -> None:
        self.order = order
        self.t0_order = t0_order
        self.start_window_s = start_window_s
        self.include_a0 = include_a0
        self.sensor = sensor
        self.method = method
        self.per_run_offset = per_run_offset

    def data_needs(self, temp_names: Sequence[str], n_runs: int) -> Needs:
        """Judged in its column as a line (the ΔT polynomial of each run rests on the
        warm-up itself, the T0 dependence on the runs' start temperatures), with
        (order + 1)(t0_order + 1) coefficients.

        Parameters
        ----------
        temp_names : sequence of str
            The temperature columns.
        n_runs : int
            Number of runs.

        Returns
        -------
        thermocal.adequacy.Needs
        """
        j = self.sensor if 0 <= self.sensor < len(temp_names) else 0
        n = (self.order + 1) * (self.t0_order + 1)
        return Needs({temp_names[j]: 1} if temp_names else {}, n)

    def chunk_context(self) -> ChunkContext:
        """T0 and F0 come from the first ``start_window_s`` seconds of the run; no Ṫ."""
        w = float(self.start_window_s)
        return ChunkContext(head_s=w if math.isfinite(w) else None, tail_s=0.0)

    # -- validation --
    def _check_params(self) -> None:
        if not (isinstance(self.order, int | np.integer) and self.order >= 1):
            raise ThermocalInputError(f"warmup: order must be an integer ≥ 1, got {self.order!r}")
        if not (isinstance(self.t0_order, int | np.integer) and self.t0_order >= 0):
            raise ThermocalInputError(
                f"warmup: t0_order must be an integer ≥ 0, got {self.t0_order!r}"
            )
        if not (isinstance(self.start_window_s, int | float) and self.start_window_s > 0):
            raise ThermocalInputError(
                f"warmup: start_window_s must be positive [s], got {self.start_window_s!r}"
            )
        if self.method not in METHODS:
            raise ThermocalInputError(
                f"warmup: unknown method {self.method!r}; use one of {', '.join(METHODS)}"
            )

    @property
    def _j0(self) -> int:
        return 0 if self.include_a0 else 1

    # -- fit --
    def fit(self, runs: Sequence[RunData]) -> Self:
        """Fit the b matrix to several power-on runs ([Seed-Plan]).

        Stage 1 (per run, post-window samples): ``ΔF = Σ_j a_j ΔT^j`` by least
        squares.  Stage 2: ``a_j = Σ_k b_jk T0^k`` over the runs by least squares
        (``method="joint"``: both at once).  Steps: the runs' start values and
        post-window changes (:func:`~thermocal.models.warmup_fit.start_values`), the
        distinct start temperatures, the scaled fit
        (:func:`~thermocal.models.warmup_fit.fit_two_stage` or
        :func:`~thermocal.models.warmup_fit.fit_joint`), the physical b
        with standard errors and the statistics (:meth:`_set_fitted`).

        Parameters
        ----------
        runs : sequence of RunData
            Runs with times [s], temperatures [°C] and signal [°/h or mg].

        Returns
        -------
        WarmupModel
            ``self``, fitted.

        Raises
        ------
        thermocal.errors.DesignError
            The data cannot determine the model (rank, ranges, segments).
        """
        self._check_params()
        if not runs:
            raise ThermocalInputError("warmup: no runs to fit")
        cols = [channel_index(self.family, r, self.sensor) for r in runs]
        one = [single_channel(r, c) for r, c in zip(runs, cols, strict=True)]
        names = {r.temp_names[0] for r in one}
        if len(names) > 1:
            raise ThermocalInputError(
                f"warmup: the runs name the temperature channel differently: {sorted(names)}"
            )
        t0s, f0s, dts, dfs = start_values(
            one, order=int(self.order), j0=self._j0, start_window_s=self.start_window_s
        )
        t0_arr = np.array(t0s)
        n_distinct = distinct_start_temperatures(t0_arr, int(self.t0_order))
        all_dt = np.concatenate(dts)
        s_dt = float(np.max(np.abs(all_dt)))
        if not s_dt > 0:
            raise DesignError(
                "warmup: the temperature does not change after the start window (ΔT ≡ 0); "
                "the ΔT terms cannot be determined"
            )
        mu = float(np.mean(t0_arr))
        sig = float(np.max(np.abs(t0_arr - mu))) or 1.0
        powers = {"order": int(self.order), "t0_order": int(self.t0_order), "j0": self._j0}
        scaled = (
            fit_two_stage(one, dts, dfs, t0_arr, (s_dt, mu, sig), **powers)
            if self.method == "two_stage"
            else fit_joint(
                one,
                dts,
                dfs,
                t0s,
                (s_dt, mu, sig),
                **powers,
                per_run_offset=bool(self.per_run_offset),
            )
        )
        if scaled.cond > CONDITION_WARN:
            warnings.warn(
                f"warmup: badly conditioned design (condition number {scaled.cond:.3g})",
                ConditioningWarning,
                stacklevel=2,
            )
        self._set_fitted(one, scaled, t0s, f0s, dts, dfs, s_dt, mu, sig, n_distinct)
        return self

    def _set_fitted(
        self,
        one: list[RunData],
        scaled: ScaledFit,
        t0s: list[float],
        f0s: list[float],
        dts: list[FloatArray],
        dfs: list[FloatArray],
        s_dt: float,
        mu: float,
        sig: float,
        n_distinct: int,
    ) -> None:
        """The physical b (``a_j = (1/s^j) Σ_k c_jk ((T0 − μ)/σ)^k``) with standard errors,
        the ranges and the residual statistics on the post-window samples."""
        order, kt, j0 = int(self.order), int(self.t0_order), self._j0
        n_j, n_k = order + 1 - j0, kt + 1
        powers_j = np.arange(j0, order + 1)
        t0_arr = np.array(t0s)
        mshift = _poly_shift_matrix(mu, sig, n_k)
        transform = np.zeros((n_j * n_k, n_j * n_k))
        for jj, j in enumerate(powers_j):
            sl = slice(jj * n_k, (jj + 1) * n_k)
            transform[sl, sl] = mshift / s_dt ** float(j)
        b_vec = transform @ scaled.c_scaled.reshape(-1)
        b = np.zeros((order + 1, n_k))
        b[j0:] = b_vec.reshape(n_j, n_k)
        self.b_ = b
        if scaled.cov_c is not None:
            cov_b = transform @ scaled.cov_c @ transform.T
            se = np.zeros((order + 1, n_k))
            se[j0:] = np.sqrt(np.maximum(np.diag(cov_b), 0.0)).reshape(n_j, n_k)
            self.b_stderr_ = se
        else:
            self.b_stderr_ = None
        self.t0_range_ = (float(t0_arr.min()), float(t0_arr.max()))
        spans = [float(r.time_s[-1] - r.time_s[0]) for r in one]
        self.duration_range_s_ = (min(spans), max(spans))
        self.sensor_name_ = one[0].temp_names[0]
        self.start_temps_ = t0_arr
        self.start_outputs_ = np.array(f0s)
        self.run_coefficients_ = (
            None
            if scaled.run_coefs is None
            else np.column_stack(
                [np.zeros((len(one), j0)), scaled.run_coefs / s_dt ** powers_j.astype(float)]
            )
        )
        resid = np.concatenate(
            [
                df - evaluate(b, np.full(dt.size, t0), dt)
                for dt, df, t0 in zip(dts, dfs, t0s, strict=True)
            ]
        )
        all_df = np.concatenate(dfs)
        sst = float(np.sum((all_df - all_df.mean()) ** 2))
        rss = float(np.sum(resid**2))
        self._record_common(
            one,
            FitStats(
                n_samples=int(all_df.size),
                n_coefficients=n_j * n_k,
                rms_residual=float(np.sqrt(np.mean(resid**2))),
                condition_number=float(scaled.cond),
                r_squared=1.0 - rss / sst if sst > 0 else None,
                dof=int(scaled.dof),
                extra={
                    "method": self.method,
                    "n_runs": len(one),
                    "n_start_temperatures": n_distinct,
                    "start_temperatures_c": [float(v) for v in t0_arr],
                },
            ),
        )

    # -- use --
    def _prepare(self, run: RunData) -> FloatArray:
        self.check_fitted()
        col = channel_index(self.family, run, self.sensor, self.sensor_name_)
        return np.asarray(run.temps_c[:, col], dtype=np.float64)

    def predict(self, run: RunData, *, extrapolate: bool = False) -> FloatArray:
        """ΔF of every sample: ``Σ_j a_j(T0_i) (T_i − T0_i)^j`` with the causal T0_i
        (running mean over the start window, then frozen) [signal unit].

        Parameters
        ----------
        run : RunData
            Times [s] and temperatures [°C].
        extrapolate : bool, optional
            False (default): temperatures clamped to the fitted range, with a warning.

        Returns
        -------
        numpy.ndarray
            Shape (n,) [signal unit].
        """
        temp = self.clamp(self._prepare(run)[:, None], extrapolate=extrapolate)[:, 0]
        self.check_duration(float(run.time_s[-1] - run.time_s[0]) if run.n_samples else 0.0)
        t0 = running_start_mean(run.time_s, temp, float(self.start_window_s))
        t0c = _clamp_range(t0, *self.t0_range_, "start temperature T0", extrapolate=extrapolate)
        # T0 is constant after the start window: a_j(T0) once, the same numbers
        m = _window_count(run.time_s, float(self.start_window_s))
        out = np.empty(run.n_samples)
        out[:m] = evaluate(self.b_, t0c[:m], temp[:m] - t0[:m])
        if run.n_samples > m:
            out[m:] = evaluate(self.b_, t0c[m : m + 1], temp[m:] - t0[m])
        return out

    DURATION_MARGIN: ClassVar[float] = 1.1
    """A record more than 10 % longer than the longest fitted power-on is warned."""

    def check_duration(self, elapsed_s: float) -> None:
        """:class:`ExtrapolationWarning` when a record runs longer after power-on than any
        fitted run (a model fitted on 900 s power-ons applied to 21 h): the
        warm-up polynomial in ΔT says nothing about the time beyond.

        Parameters
        ----------
        elapsed_s : float
            Time since the record's first sample [s].
        """
        rng = self.duration_range_s_
        if rng is None or not elapsed_s > self.DURATION_MARGIN * rng[1]:
            return
        warnings.warn(
            f"warmup: the record runs {elapsed_s:.6g} s after power-on, but the model was "
            f"fitted on power-ons of {rng[0]:.6g}…{rng[1]:.6g} s; beyond that the warm-up "
            "curve is an extrapolation (fit on longer runs, or use a chamber model for "
            "steady operation)",
            ExtrapolationWarning,
            stacklevel=3,
        )

    def stream(self, sample_interval_s: float, *, extrapolate: bool = False) -> ModelStream:
        """Sample-by-sample twin of :meth:`predict` (T0 captured at power-on).

        Parameters
        ----------
        sample_interval_s : float
            Nominal sample interval [s].
        extrapolate : bool, optional
            Default False.

        Returns
        -------
        WarmupStream
        """
        self.check_fitted()
        return WarmupStream(self, extrapolate=extrapolate)

    def a_of_t0(self, t0_c: float | npt.ArrayLike) -> FloatArray:
        """Coefficients ``a_j(T0) = Σ_k b_jk T0^k`` for start temperature(s) T0 [°C];
        shape (order+1,) or (n, order+1).

        Parameters
        ----------
        t0_c : float or array_like
            Start temperature(s) T0 [°C].

        Returns
        -------
        numpy.ndarray
            a_j [signal unit / °C^j].

        Notes
        -----
        .. math:: a_j(T_0) = \\sum_k b_{jk} T_0^k
        """
        self.check_fitted()
        x = np.asarray(t0_c, dtype=np.float64)
        out = np.stack(
            [horner(self.b_[j], np.atleast_1d(x)) for j in range(self.b_.shape[0])], axis=-1
        )
        return out[0] if x.ndim == 0 else out

    def coefficients(self) -> list[Coefficient]:
        """The b matrix ``b_jk`` [signal unit / °C^(j+k)], with standard errors."""
        self.check_fitted()
        out = []
        unit = self.signal_unit
        for j in range(self._j0, self.b_.shape[0]):
            for k in range(self.b_.shape[1]):
                p = j + k
                out.append(
                    Coefficient(
                        name=f"b{j}{k}",
                        value=float(self.b_[j, k]),
                        stderr=None if self.b_stderr_ is None else float(self.b_stderr_[j, k]),
                        unit=unit if p == 0 else f"{unit}/degC^{p}" if p > 1 else f"{unit}/degC",
                    )
                )
        return out

    @classmethod
    def check_state(cls, d: dict[str, Any], root: str = "") -> None:
        """The ``state`` section of a warmup model file: ``b`` of (order + 1) × (t0_order +
        1) (or without the constant row) finite numbers; ``params.sensor`` one of the inputs.

        Parameters
        ----------
        d : dict
            The model file's content.
        root : str, optional
            Key path prefix.  Default ``""``.

        Raises
        ------
        thermocal.errors.ModelFileError
            A bad state, naming the key path.
        """
        sensor_param(d, root)
        state, path = d["state"], key_path(root, "state")
        fields(
            {"b": matrix, "order": integer, "t0_order": integer, "sensor_name": string,
             "t0_range_c": interval},
            optional={"b_stderr": matrix, "start_window_s": number, "duration_range_s": interval},
        )(state, path)  # fmt: skip
        rows, cols = len(state["b"]), len(state["b"][0]) if state["b"] else 0
        want = (state["order"] + 1, state["t0_order"] + 1)
        if (rows, cols) not in (want, (want[0] - 1, want[1])):
            raise ModelFileError(
                f"{path}.b: expected a {want[0]}×{want[1]} (or {want[0] - 1}×{want[1]}, without "
                f"the constant) matrix for order {state['order']} and t0_order "
                f"{state['t0_order']}, got {rows}×{cols}"
            )
        for i, row in enumerate(state["b"]):
            for j, v in enumerate(row):
                number(v, f"{path}.b[{i}][{j}]")

    def _state(self) -> dict[str, Any]:
        return {
            "b": self.b_.tolist(),
            "b_stderr": None if self.b_stderr_ is None else self.b_stderr_.tolist(),
            "order": int(self.order),
            "t0_order": int(self.t0_order),
            "start_window_s": float(self.start_window_s),
            "sensor_name": self.sensor_name_,
            "t0_range_c": list(self.t0_range_),
            "duration_range_s": (
                None if self.duration_range_s_ is None else list(self.duration_range_s_)
            ),
            "start_temps_c": self.start_temps_.tolist(),
            "start_outputs": self.start_outputs_.tolist(),
            "run_coefficients": (
                None if self.run_coefficients_ is None else self.run_coefficients_.tolist()
            ),
        }

    def _set_state(self, state: dict[str, Any]) -> None:
        self.b_ = np.array(state["b"], dtype=np.float64)
        se = state.get("b_stderr")
        self.b_stderr_ = None if se is None else np.array(se, dtype=np.float64)
        self.sensor_name_ = str(state["sensor_name"])
        lo, hi = state["t0_range_c"]
        self.t0_range_ = (float(lo), float(hi))
        dur = state.get("duration_range_s")  # absent in older files
        self.duration_range_s_ = None if dur is None else (float(dur[0]), float(dur[1]))
        self.start_temps_ = np.array(state.get("start_temps_c", []), dtype=np.float64)
        self.start_outputs_ = np.array(state.get("start_outputs", []), dtype=np.float64)
        rc = state.get("run_coefficients")
        self.run_coefficients_ = None if rc is None else np.array(rc, dtype=np.float64)
