"""The bank's choice at power-on ([Seed-Accel], step 4): the :class:`Selection` (chosen
model, every model's deviation, the margin) and :class:`BankStream`, the sample-by-sample
twin of :meth:`thermocal.models.bank.BankModel.predict` (running residual sums during the
start-up window, then the frozen choice).
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from thermocal.errors import ThermocalInputError
from thermocal.models.base import ModelStream
from thermocal.models.streams import ClampOnce, stream_channel
from thermocal.recording import FloatArray

if TYPE_CHECKING:
    from thermocal.models.bank import BankModel


@dataclass(frozen=True)
class Selection:
    """The model chosen at power-on.

    Attributes
    ----------
    index : int
        Index of the chosen model in the bank.
    deviations : tuple of float
        D_m of every model [signal unit].
    margin : float
        Runner-up − best deviation [signal unit] (inf with one model).
    n_samples : int
        Start-up samples used.
    complete : bool
        True once the start-up window (``startup_s``) was full.
    """

    index: int
    deviations: tuple[float, ...]
    margin: float
    n_samples: int
    complete: bool

    def to_dict(self) -> dict[str, Any]:
        """JSON form of the selection."""
        return {
            "index": self.index,
            "deviations": list(self.deviations),
            "margin": self.margin if math.isfinite(self.margin) else None,
            "n_samples": self.n_samples,
            "complete": self.complete,
        }


def selection_of(dev: FloatArray, n: int, complete: bool) -> Selection:
    """The model with the smallest deviation and its margin over the runner-up.

    Parameters
    ----------
    dev : numpy.ndarray
        D_m of every model [signal unit].
    n : int
        Start-up samples used.
    complete : bool
        The start-up window was full.

    Returns
    -------
    Selection
        ``argmin_m D_m`` (first index on ties) and the margin (inf with one model).
    """
    order = np.argsort(dev, kind="stable")
    best = int(np.argmin(dev))
    margin = float(dev[order[1]] - dev[best]) if dev.size > 1 else math.inf
    return Selection(best, tuple(float(v) for v in dev), margin, n, complete)


class BankStream(ModelStream):
    """Streaming twin of :meth:`BankModel.predict`, in plain Python floats: running
    residual sums per model during the start-up window, then the frozen choice (only
    the chosen model is evaluated after it).  The same operations as ``predict``
    (:func:`pwl_evaluate`, the cumulative sums of ``_run_selection``), so the same numbers.

    ``temps_c`` holds either one value (the model's channel) or the fitted run's
    channels (``sensor`` picks).  ``signal`` (raw; ``known_input`` is subtracted) is
    required during the start-up window.  ``selection`` is the current :class:`Selection`.
    Warns once per stream when a temperature leaves the fitted range.

    Parameters
    ----------
    model : BankModel
        The fitted bank.
    extrapolate : bool, optional
        Default False.
    known_input : float, optional
        Known input subtracted from the signal [signal unit].  Default 0.
    """

    def __init__(
        self, model: BankModel, *, extrapolate: bool = False, known_input: float = 0.0
    ) -> None:
        self.model = model
        self.extrapolate = extrapolate
        self.known_input = float(known_input)
        self._col = int(model.sensor)
        lo, hi = (float(v) for v in model.temp_range_[0])
        self._clamp = ClampOnce(lo, hi, extrapolate=extrapolate)
        self._startup = float(model.startup_s)
        self._xs = [[float(x) for x in b] for b in model.breakpoints_]
        self._vs = [[float(v) for v in vals] for vals in model.values_]
        self.reset()

    def reset(self) -> None:
        """Forget everything (a new power-on): the start-up selection starts again."""
        n = len(self._vs)
        self._t_first: float | None = None
        self._sums = [0.0] * n
        self._count = 0
        self._frozen = False
        self._choice = 0
        self._dev = [math.nan] * n
        self._clamp.warned = False

    @property
    def selection(self) -> Selection:
        """The current :class:`Selection`."""
        return selection_of(np.array(self._dev, dtype=np.float64), self._count, self._frozen)

    def _value(self, m: int, temp: float) -> float:
        """Model m at T: :func:`pwl_evaluate` on one float (same operations)."""
        x, v = self._xs[m], self._vs[m]
        j = min(max(bisect.bisect_right(x, temp) - 1, 0), len(x) - 2)
        slope = (v[j + 1] - v[j]) / (x[j + 1] - x[j])
        return v[j] + slope * (temp - x[j])

    def update(self, time_s: float, temps_c: FloatArray, signal: float | None = None) -> float:
        """Model value for one sample (see :meth:`ModelStream.update`).

        Parameters
        ----------
        time_s : float
            Sample time [s].
        temps_c : numpy.ndarray
            Temperatures [°C].
        signal : float, optional
            Raw signal [signal unit]; required during the start-up window.

        Returns
        -------
        float
            The selected model's value [signal unit].

        Raises
        ------
        thermocal.errors.ThermocalInputError
            No signal during the start-up window.
        """
        temp = self._clamp(stream_channel(temps_c, self._col))
        t = float(time_s)
        if self._t_first is None:
            self._t_first = t
        if not self._frozen and t - self._t_first < self._startup:
            if signal is None:
                raise ThermocalInputError(
                    "bank: selecting a model at power-on needs the measured signal"
                )
            y = float(signal) - self.known_input
            f = [self._value(m, temp) for m in range(len(self._vs))]
            self._count += 1
            sums = self._sums
            best = 0
            for m, fm in enumerate(f):
                sums[m] = sums[m] + (y - fm)
                dev = abs(sums[m] / self._count)
                self._dev[m] = dev
                if dev < self._dev[best]:
                    best = m
            self._choice = best
            return f[best]
        self._frozen = True
        return self._value(self._choice, temp)
