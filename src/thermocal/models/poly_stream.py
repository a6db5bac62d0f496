"""The polynomial model's streaming twin: :class:`PolyStream` evaluates a fitted
:class:`thermocal.models.poly.PolyModel` sample by sample in plain Python floats (a ring
buffer of the last rate interval for the backward Ṫ), with the same operations and the
same numbers as its ``predict`` (:class:`~thermocal.models.poly_types.EvalPlan`).
"""

from __future__ import annotations

import math
import warnings
from collections import deque
from typing import TYPE_CHECKING

import numpy as np

from thermocal.errors import ExtrapolationWarning, ThermocalInputError
from thermocal.models.base import ModelStream
from thermocal.recording import GAP_FACTOR, FloatArray
from thermocal.units import SECONDS_PER_MINUTE

if TYPE_CHECKING:
    from thermocal.models.poly import PolyModel


class PolyStream(ModelStream):
    """Sample-by-sample :class:`PolyModel` (module docstring steps 1–4), in plain Python
    floats: the same operations as :meth:`PolyModel.predict`
    (:class:`~thermocal.models.poly_types.EvalPlan`).

    Keeps the samples of the last Δt of the current contiguous segment for the
    backward rate (a ring buffer; the partner is the oldest sample with
    ``t_j ≥ t − Δt``, as ``searchsorted`` in the batch); a step longer than
    ``GAP_FACTOR × sample_interval_s`` starts a new segment (rate restarts from 0).
    Warns once per stream (per kind: temperature, rate) when a sample leaves the
    fitted range.

    Parameters
    ----------
    model : PolyModel
        The fitted model.
    sample_interval_s : float
        Nominal sample interval [s].
    extrapolate : bool
        Keep out-of-range inputs (and warn).

    Raises
    ------
    thermocal.errors.ThermocalInputError
        A sample interval that is not positive.
    """

    def __init__(self, model: PolyModel, sample_interval_s: float, *, extrapolate: bool) -> None:
        if not sample_interval_s > 0:
            raise ThermocalInputError(f"sample interval must be positive, got {sample_interval_s}")
        plan = model._plan()
        self.model = model
        self.extrapolate = extrapolate
        self.gap_s = GAP_FACTOR * float(sample_interval_s)
        self.interval_s = float(model.rate_interval_s)
        self.uses_rate = bool(plan.rate_sensors)
        self._k = int(model.temp_range_.shape[0])
        self._t_lo: list[float] = [float(v) for v in model.temp_range_[:, 0]]
        self._t_hi: list[float] = [float(v) for v in model.temp_range_[:, 1]]
        self._t_bounds = list(zip(range(self._k), self._t_lo, self._t_hi, strict=True))
        rr = model.rate_range_
        # (column, lo, hi) of every Ṫ the terms use; ±inf without a fitted rate range
        self._rate_spec: list[tuple[int, float, float]] = [
            (j, float(rr[j, 0]), float(rr[j, 1])) if rr is not None else (j, -math.inf, math.inf)
            for j in plan.rate_sensors
        ]
        self._const = plan.constant
        self._rows = plan.py_rows
        self.reset()

    def reset(self) -> None:
        """Forget everything (a new power-on): the Ṫ history restarts."""
        self._times: deque[float] = deque()
        self._hist: deque[list[float]] = deque()
        self._last_t: float | None = None
        self._warned_t = False
        self._warned_r = False

    def _warn(self, what: str) -> None:
        action = "extrapolating" if self.extrapolate else "clamped to the fitted range"
        warnings.warn(
            f"{what} outside the model's fitted range; {action}", ExtrapolationWarning, stacklevel=3
        )

    def update(self, time_s: float, temps_c: FloatArray, signal: float | None = None) -> float:
        """Model value for one sample (see :meth:`ModelStream.update`).

        Parameters
        ----------
        time_s : float
            Sample time [s].
        temps_c : numpy.ndarray
            Temperatures [°C].
        signal : float, optional
            Not used.

        Returns
        -------
        float
            [signal unit].
        """
        t = float(time_s)
        if type(temps_c) is np.ndarray and temps_c.dtype == np.float64 and temps_c.ndim == 1:
            row: list[float] = temps_c.tolist()
        else:
            row = np.asarray(temps_c, dtype=np.float64).reshape(-1).tolist()
        if len(row) != self._k:
            raise ThermocalInputError(
                f"poly model uses {self._k} temperature channels; the sample has {len(row)}"
            )
        rates = row  # placeholder, replaced when the model uses Ṫ
        if self.uses_rate:
            times, hist = self._times, self._hist
            if self._last_t is not None and t - self._last_t > self.gap_s:
                times.clear()
                hist.clear()
            self._last_t = t
            times.append(t)
            hist.append(row)
            x = t - self.interval_s
            while times[0] < x:
                times.popleft()
                hist.popleft()
            span = t - times[0]
            rates = [0.0] * self._k
            old = hist[0]
            for j, lo, hi in self._rate_spec:
                r = (row[j] - old[j]) / span * SECONDS_PER_MINUTE if span > 0 else 0.0
                if r < lo or r > hi:
                    if not self._warned_r:
                        self._warned_r = True
                        self._warn("temperature rate")
                    if not self.extrapolate:
                        r = lo if r < lo else hi
                rates[j] = r
        temps = row
        for j, lo, hi in self._t_bounds:
            v = row[j]
            if v < lo or v > hi:
                if not self._warned_t:
                    self._warned_t = True
                    self._warn("temperature")
                if not self.extrapolate:
                    if temps is row:
                        temps = list(row)
                    temps[j] = lo if v < lo else hi
        y = self._const
        for col, tc, rc, wc, polys, mixed in self._rows:
            temp = temps[col]
            s: float | None = None
            for kind, top, rest in polys:
                if kind == 0:
                    d = temp - tc
                elif kind == 1:
                    d = rates[col] - rc
                else:
                    d = temp * rates[col] - wc
                acc = d * top
                for cp in rest:
                    acc = (acc + cp) * d
                s = acc if s is None else s + acc
            if s is None:
                s = 0.0
            for cf, factors in mixed:
                ds = [temp - tc, rates[col] - rc, temp * rates[col] - wc]
                m = ds[factors[0]] * cf
                for f in factors[1:]:
                    m = m * ds[f]
                s = s + m
            y = y + s
        return y
