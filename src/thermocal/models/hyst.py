r"""Thermal-hysteresis model: a polynomial in the die temperature, the die a first-order lag
of the measured temperature (Niu et al. 2013; Kim & Jung 2025).

.. math::

    \tau \dot z = T - z, \qquad
    \hat y = \sum_{j=0}^{p} a_j \left(\frac{z - \mu}{s}\right)^j                (1)

with ``T`` the recorded temperature (the first temperature column) clamped to the fitted
range, ``z`` its lag from ``z = T`` at the first sample (exact first-order hold,
:func:`thermocal.models.hyst_lag.first_order_lag`), ``μ`` and ``s`` the centre and half
width of the fitted range.  τ is given (``tau_s``) or fitted by a 1-D search minimising the
residual sum of squares (:func:`thermocal.models.hyst_lag.search_tau`), with its standard
error from the curvature of that sum.  A model fitted on heating alone and applied on
cooling (the fit's ``legs`` option, then a validation) is the check of the lag: the two legs'
residuals agree when τ is right.

Model-file ``state`` layout (``"layout": "thermocal-hyst-1"``), for the C export::

    {
      "layout": "thermocal-hyst-1",
      "temperature": "T1",          # the one temperature used
      "order": p,
      "tau_s": τ, "tau_stderr_s": σ_τ or null, "tau_fitted": true | false,
      "centre_c": μ, "scale_c": s,  # [°C]
      "coefficients": [a0, ..., ap],  "coefficient_stderr": [...]
    }

Evaluation of one sample: ``T`` clamped to ``range.temperature_c``; at the first sample
``z = T``, then ``z ← e z + (1 − c) T + (c − e) T_prev`` with ``e = exp(−h/τ)``,
``c = (τ/h)(1 − e)``, ``h`` the time step (``z`` kept when ``h ≤ 0``); ``u = (z − μ)/s``;
``y = Σ a_j u^j`` by Horner's rule.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, ClassVar, Self

import numpy as np

from thermocal.adequacy import Needs
from thermocal.errors import DesignError, ModelFileError, ThermocalInputError
from thermocal.families import HYST, FamilyDeclaration
from thermocal.models.base import ChunkContext, ModelStream, TemperatureModel
from thermocal.models.checks import (
    boolean,
    fields,
    integer,
    key_path,
    list_of,
    number,
    number_or_null,
    string,
)
from thermocal.models.fitting import check_runs
from thermocal.models.hyst_lag import first_order_lag, fit_at, search_tau
from thermocal.models.numerics import channel_index, horner, single_channel
from thermocal.models.results import Coefficient, FitStats
from thermocal.models.rundata import RunData
from thermocal.models.streams import ClampOnce, stream_channel
from thermocal.recording import FloatArray, median_interval

STATE_LAYOUT = "thermocal-hyst-1"


class HystModel(TemperatureModel):
    """Polynomial in the lagged (die) temperature; see the module docstring.

    Parameters
    ----------
    order : int
        Polynomial order p in the die temperature (default 3).
    tau_s : float, optional
        The lag τ [s] held fixed (0: no lag, a plain polynomial); None (default): fitted.
    tau_max_s : float, optional
        Upper bound of the search [s] (default half the longest run).

    Notes
    -----
    .. math:: \\tau \\dot z = T - z, \\qquad \\hat y = \\sum_j a_j ((z-\\mu)/s)^j

    References
    ----------
    - X. Niu, Y. Li, H. Zhang, Q. Wang and Y. Ban, "Fast thermal calibration of low-grade
      inertial sensors and inertial measurement units", *Sensors* 13 (2013) 12192–12217.
    - Kim and Jung (2025), thermal hysteresis of a MEMS IMU's bias between heating and
      cooling (docs/methods.md, [KimJung2025]).

    Examples
    --------
    >>> import numpy as np
    >>> from thermocal.models import RunData
    >>> from thermocal.models.hyst_lag import first_order_lag
    >>> t = np.arange(0.0, 7200.0, 2.0)
    >>> T = np.interp(t, [0, 600, 3000, 3600, 6000, 7200], [20, 20, 60, 60, 20, 20])
    >>> y = 0.5 * (first_order_lag(t, T, 120.0) - 40.0)
    >>> m = HystModel(order=1).fit([RunData(t, T[:, None], y, ("T1",))])
    >>> round(m.tau_, 3), round(float(m.residuals(RunData(t, T[:, None], y, ("T1",))).std()), 4)
    (120.0, 0.0)
    """

    declaration: ClassVar[FamilyDeclaration] = HYST
    uses_rate: ClassVar[bool] = False

    tau_: float
    tau_stderr_: float | None
    tau_fitted_: bool
    coef_: FloatArray
    coef_stderr_: FloatArray
    centre_: float
    scale_: float
    sensor_name_: str

    def __init__(
        self, order: int = 3, tau_s: float | None = None, tau_max_s: float | None = None
    ) -> None:
        self.order = order
        self.tau_s = tau_s
        self.tau_max_s = tau_max_s

    LAG_MEMORY: ClassVar[float] = 40.0
    """History before a chunk, in time constants: the lag restarted there forgets its
    starting error by e^−40 ≈ 4e−18, below a double's resolution of the temperature."""

    def chunk_context(self) -> ChunkContext:
        """40 τ of history before a chunk (:attr:`LAG_MEMORY`): the same values as the whole
        record's lag to the last bit of a double."""
        return ChunkContext(head_s=0.0, tail_s=self.LAG_MEMORY * float(getattr(self, "tau_", 0.0)))

    def data_needs(self, temp_names: Sequence[str], n_runs: int) -> Needs:
        """The polynomial's order in the first temperature column; p + 1 coefficients and
        τ when fitted.

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
        n = int(self.order) + 1 + (1 if self.tau_s is None else 0)
        return Needs({temp_names[0]: int(self.order)} if temp_names else {}, n)

    def _check_params(self) -> None:
        if not (isinstance(self.order, int | np.integer) and self.order >= 1):
            raise ThermocalInputError(f"hyst: order must be an integer ≥ 1, got {self.order!r}")
        for name in ("tau_s", "tau_max_s"):
            v = getattr(self, name)
            if v is not None and not (isinstance(v, int | float) and math.isfinite(v) and v >= 0):
                raise ThermocalInputError(f"hyst: {name} must be a finite number ≥ 0, got {v!r}")

    def fit(self, runs: Sequence[RunData]) -> Self:
        """Fit eq. (1): τ given or found by :func:`~thermocal.models.hyst_lag.search_tau`
        between the median sample interval and ``tau_max_s``, then the polynomial by least
        squares at τ.

        Parameters
        ----------
        runs : sequence of RunData
            Runs with times [s], temperatures [°C] and signal [°/h or mg]; each run's lag
            starts at its first sample.

        Returns
        -------
        HystModel
            ``self``, fitted.

        Raises
        ------
        thermocal.errors.DesignError
            No temperature span, or fewer samples than coefficients.
        """
        self._check_params()
        rl = check_runs(runs, self.family)
        one = [single_channel(r, channel_index(self.family, r, 0)) for r in rl]
        times = [np.asarray(r.time_s, dtype=np.float64) for r in one]
        temps = [np.ascontiguousarray(r.temps_c[:, 0]) for r in one]
        y = np.concatenate([r.target() for r in one])
        lo = min(float(x.min()) for x in temps)
        hi = max(float(x.max()) for x in temps)
        if not hi > lo:
            raise DesignError("hyst: the temperature does not change; no polynomial in it")
        if y.size <= int(self.order) + 2:
            raise DesignError(f"hyst: {y.size} samples cannot fit {int(self.order) + 2} values")
        cs = (0.5 * (lo + hi), 0.5 * (hi - lo))
        if self.tau_s is not None:
            best, sigma, fitted = (
                fit_at(times, temps, y, float(self.tau_s), int(self.order), cs),
                None,
                False,
            )
        else:
            step = min(median_interval(t) for t in times if t.size > 1)
            longest = max(float(t[-1] - t[0]) for t in times)
            upper = float(self.tau_max_s) if self.tau_max_s else 0.5 * longest
            if not upper > step:
                raise DesignError.naming(
                    f"hyst: the lag search needs an upper bound above the sample interval "
                    f"{step:.3g} s, got {upper:.3g} s (give {{tau_max_s}} or {{tau_s}})",
                    "tau_max_s",
                    "tau_s",
                )
            best, sigma = search_tau(times, temps, y, int(self.order), cs, (step, upper))
            fitted = True
        self.tau_, self.tau_stderr_, self.tau_fitted_ = best.tau_s, sigma, fitted
        self.coef_ = best.coefficients
        self.coef_stderr_ = np.sqrt(np.maximum(np.diag(best.cov), 0.0))
        self.centre_, self.scale_ = cs
        self.sensor_name_ = one[0].temp_names[0]
        sst = float(np.sum((y - y.mean()) ** 2))
        stats = FitStats(
            n_samples=int(y.size),
            n_coefficients=int(self.order) + 1 + int(fitted),
            rms_residual=float(np.sqrt(best.rss / y.size)),
            condition_number=best.cond,
            r_squared=1.0 - best.rss / sst if sst > 0 else None,
            dof=int(y.size - int(self.order) - 1 - int(fitted)),
            extra={"tau_s": self.tau_, "tau_stderr_s": sigma, "tau_fitted": fitted},
        )
        self._record_common(one, stats)
        return self

    def _column(self, run: RunData) -> FloatArray:
        self.check_fitted()
        col = channel_index(self.family, run, 0, self.sensor_name_)
        return np.asarray(run.temps_c[:, col], dtype=np.float64)

    def die_temperature(self, run: RunData, *, extrapolate: bool = False) -> FloatArray:
        """The lagged temperature z of every sample [°C] (the reading clamped first).

        Parameters
        ----------
        run : RunData
            Times [s] and temperatures [°C].
        extrapolate : bool, optional
            As in :meth:`predict`.

        Returns
        -------
        numpy.ndarray
            z, shape (n,) [°C].
        """
        temp = self.clamp(self._column(run)[:, None], extrapolate=extrapolate)[:, 0]
        return first_order_lag(np.asarray(run.time_s, dtype=np.float64), temp, self.tau_)

    def predict(self, run: RunData, *, extrapolate: bool = False) -> FloatArray:
        """Eq. (1) at every sample [signal unit].

        Parameters
        ----------
        run : RunData
            Times [s] and temperatures [°C]; the lag starts at its first sample.
        extrapolate : bool, optional
            False (default): temperatures clamped to the fitted range, with a warning.

        Returns
        -------
        numpy.ndarray
            Shape (n,) [signal unit].
        """
        z = self.die_temperature(run, extrapolate=extrapolate)
        out: FloatArray = horner(self.coef_, (z - self.centre_) / self.scale_)
        return out

    def stream(self, sample_interval_s: float, *, extrapolate: bool = False) -> ModelStream:
        """Sample-by-sample twin of :meth:`predict`.

        Parameters
        ----------
        sample_interval_s : float
            Nominal sample interval [s] (not used: the lag takes each step as it is).
        extrapolate : bool, optional
            Default False.

        Returns
        -------
        HystStream
        """
        self.check_fitted()
        return HystStream(self, extrapolate=extrapolate)

    def coefficients(self) -> list[Coefficient]:
        """τ [s] and the polynomial's ``a_j`` of ``u = (z − μ)/s`` [signal unit]."""
        self.check_fitted()
        out = [Coefficient("tau", self.tau_, self.tau_stderr_, "s")]
        for j, (v, se) in enumerate(zip(self.coef_, self.coef_stderr_, strict=True)):
            out.append(Coefficient(f"a{j}", float(v), float(se), self.signal_unit))
        return out

    @classmethod
    def check_state(cls, d: dict[str, Any], root: str = "") -> None:
        """The ``state`` of a hyst model file: the layout, τ ≥ 0, a positive scale and
        ``order + 1`` finite coefficients.

        Parameters
        ----------
        d : dict
            The model file's content.
        root : str, optional
            Key path prefix.

        Raises
        ------
        thermocal.errors.ModelFileError
            A bad state, naming the key path.
        """
        state, path = d["state"], key_path(root, "state")
        fields(
            {"layout": string, "temperature": string, "order": integer, "tau_s": number,
             "centre_c": number, "scale_c": number, "coefficients": list_of(number, min_len=2)},
            optional={"tau_stderr_s": number_or_null, "tau_fitted": boolean,
                      "coefficient_stderr": list_of(number)},
        )(state, path)  # fmt: skip
        if state["layout"] != STATE_LAYOUT:
            raise ModelFileError(
                f"{path}.layout: expected {STATE_LAYOUT!r}, got {state['layout']!r}"
            )
        if state["tau_s"] < 0 or not state["scale_c"] > 0:
            raise ModelFileError(f"{path}: tau_s must be ≥ 0 and scale_c > 0")
        if len(state["coefficients"]) != state["order"] + 1:
            raise ModelFileError(
                f"{path}.coefficients: order {state['order']} needs {state['order'] + 1} "
                f"coefficients, got {len(state['coefficients'])}"
            )

    def _state(self) -> dict[str, Any]:
        return {
            "layout": STATE_LAYOUT,
            "temperature": self.sensor_name_,
            "order": int(self.coef_.size - 1),
            "tau_s": float(self.tau_),
            "tau_stderr_s": self.tau_stderr_,
            "tau_fitted": bool(self.tau_fitted_),
            "centre_c": float(self.centre_),
            "scale_c": float(self.scale_),
            "coefficients": [float(v) for v in self.coef_],
            "coefficient_stderr": [float(v) for v in self.coef_stderr_],
        }

    def _set_state(self, state: dict[str, Any]) -> None:
        self.tau_ = float(state["tau_s"])
        se = state.get("tau_stderr_s")
        self.tau_stderr_ = None if se is None else float(se)
        self.tau_fitted_ = bool(state.get("tau_fitted", False))
        self.centre_ = float(state["centre_c"])
        self.scale_ = float(state["scale_c"])
        self.coef_ = np.array(state["coefficients"], dtype=np.float64)
        cse = state.get("coefficient_stderr") or [0.0] * self.coef_.size
        self.coef_stderr_ = np.array(cse, dtype=np.float64)
        self.sensor_name_ = str(state["temperature"])


class HystStream(ModelStream):
    """Sample-by-sample :class:`HystModel`: the clamped reading, the lag's recursion in
    plain floats and Horner's rule (the same operations as :meth:`HystModel.predict`).

    Parameters
    ----------
    model : HystModel
        The fitted model.
    extrapolate : bool
        Keep out-of-range temperatures (and warn).
    """

    def __init__(self, model: HystModel, *, extrapolate: bool) -> None:
        self.model = model
        lo, hi = (float(v) for v in model.temp_range_[0])
        self._clamp = ClampOnce(lo, hi, extrapolate=extrapolate)
        self._tau = float(model.tau_)
        self._coef = [float(v) for v in model.coef_]
        self._centre, self._scale = float(model.centre_), float(model.scale_)
        self.reset()

    def reset(self) -> None:
        """Forget everything (a new power-on: the lag restarts at the reading)."""
        self._clamp.warned = False
        self._z: float | None = None
        self._t = 0.0
        self._x = 0.0

    def update(self, time_s: float, temps_c: FloatArray, signal: float | None = None) -> float:
        """Model value for one sample (see :meth:`ModelStream.update`).

        Parameters
        ----------
        time_s : float
            Sample time [s].
        temps_c : numpy.ndarray
            Temperatures [°C] (the model's only, or every fitted column).
        signal : float, optional
            Not used.

        Returns
        -------
        float
            Eq. (1) [signal unit].
        """
        x = self._clamp(stream_channel(temps_c, 0))
        if self._z is None or self._tau <= 0:
            z = x
        else:
            h = time_s - self._t
            z = self._z
            if h > 0:
                q = h / self._tau
                e = math.exp(-q)
                c = -math.expm1(-q) / q
                z = e * z + (1.0 - c) * x + (c - e) * self._x
        self._z, self._t, self._x = z, time_s, x
        u = (z - self._centre) / self._scale
        y = self._coef[-1]  # Horner's rule, the operations of numerics.horner
        for c in self._coef[-2::-1]:
            y = y * u + c
        return y
