"""The warm-up model's streaming twin: :class:`WarmupStream` evaluates a fitted
:class:`thermocal.models.warmup.WarmupModel` sample by sample in plain Python floats (the
firmware's arithmetic), with the same numbers as its ``predict``.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from thermocal.errors import ExtrapolationWarning
from thermocal.models.base import ModelStream
from thermocal.recording import FloatArray

if TYPE_CHECKING:
    from thermocal.models.warmup import WarmupModel


def _horner_py(coef: Sequence[float], x: float) -> float:
    """:func:`horner` on one Python float (the same operations, in the same order)."""
    acc = coef[-1]
    for c in coef[-2::-1]:
        acc = acc * x + c
    return acc


class WarmupStream(ModelStream):
    """Streaming twin of :meth:`WarmupModel.predict`, in plain Python floats: keeps the
    start-window sum of T (running mean T0, frozen when the window is full) and, once
    frozen, the coefficients ``a_j(T0)``.  The same operations as ``predict``
    (:func:`running_start_mean`, :func:`horner`, :func:`thermocal.models.warmup_fit.evaluate`),
    so the same numbers.

    ``temps_c`` holds either one value (the model's channel) or the channels of the
    fitted runs (``sensor`` picks); the signal is not used.  Warns once per stream (per
    kind: temperature, start temperature) when a value leaves the fitted range.

    Parameters
    ----------
    model : WarmupModel
        The fitted model.
    extrapolate : bool, optional
        Default False.
    """

    def __init__(self, model: WarmupModel, *, extrapolate: bool = False) -> None:
        self.model = model
        self.extrapolate = extrapolate
        self._col = int(model.sensor)
        self._lo = float(model.temp_range_[0, 0])
        self._hi = float(model.temp_range_[0, 1])
        self._t0_lo, self._t0_hi = (float(v) for v in model.t0_range_)
        self._window = float(model.start_window_s)
        self._b = [[float(v) for v in row] for row in model.b_]
        span = model.duration_range_s_
        self._max_span = None if span is None else model.DURATION_MARGIN * float(span[1])
        self.reset()

    def reset(self) -> None:
        """Forget everything (a new power-on): T0 is captured again."""
        self._t_first: float | None = None
        self._sum = 0.0
        self._count = 0
        self._frozen = False
        self._t0 = math.nan
        self._a: list[float] | None = None  # a_j(T0) once T0 is frozen
        self._warned_t = False
        self._warned_t0 = False
        self._warned_span = False

    @property
    def t0_c(self) -> float:
        """The start temperature T0 [°C] so far (running mean until frozen)."""
        return self._t0

    def _warn(self, what: str) -> None:
        action = "extrapolating" if self.extrapolate else "clamped to the fitted range"
        warnings.warn(
            f"{what} outside the model's fitted range; {action}",
            ExtrapolationWarning,
            stacklevel=3,
        )

    def _coefficients(self, t0: float) -> list[float]:
        """``a_j(clamp(T0))`` (with the T0 range warning)."""
        t0c = t0
        if t0 < self._t0_lo or t0 > self._t0_hi:
            if not self._warned_t0:
                self._warned_t0 = True
                self._warn("start temperature T0")
            if not self.extrapolate:
                t0c = min(max(t0, self._t0_lo), self._t0_hi)
        return [_horner_py(bj, t0c) for bj in self._b]

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
        if type(temps_c) is np.ndarray and temps_c.dtype == np.float64 and temps_c.ndim == 1:
            arr = temps_c
        else:
            arr = np.asarray(temps_c, dtype=np.float64).reshape(-1)
        # one value: the model's channel; several: the fitted run's channels, use ``sensor``
        temp = float(arr.item(0) if arr.size == 1 else arr.item(self._col))
        if temp < self._lo or temp > self._hi:
            if not self._warned_t:
                self._warned_t = True
                self._warn("temperature")
            if not self.extrapolate:
                temp = min(max(temp, self._lo), self._hi)
        t = float(time_s)
        if self._t_first is None:
            self._t_first = t
        if (
            not self._warned_span
            and self._max_span is not None
            and t - self._t_first > self._max_span
        ):
            self._warned_span = True
            self.model.check_duration(t - self._t_first)
        if not self._frozen and t - self._t_first < self._window:
            self._sum = self._sum + temp
            self._count += 1
            self._t0 = self._sum / self._count
            a = self._coefficients(self._t0)
        else:
            if not self._frozen:
                self._frozen = True
                if self._count == 0:  # pragma: no cover - the first sample is always in
                    self._t0 = temp
            if self._a is None:
                self._a = self._coefficients(self._t0)
            a = self._a
        dt = temp - self._t0
        out = a[-1]
        for aj in a[-2::-1]:
            out = out * dt + aj
        return out
