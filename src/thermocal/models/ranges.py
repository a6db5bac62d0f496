"""How far a run leaves a model's calibrated ranges (temperature, Ṫ, time since power-on):
:class:`RangeExcess` per input, :class:`RangeTally` accumulated over the chunks of a long
file, and one warning per channel (:func:`outside_range_message`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from thermocal.recording import FloatArray

if TYPE_CHECKING:
    from thermocal.models.base import TemperatureModel

# --- applicability: how far a run leaves the calibrated ranges --------------------------------

RANGE_WARNING_PATTERNS: tuple[str, ...] = (
    r".*samples outside the model's temperature range",
    r"temperature rate outside the model's fitted range",
    r"warmup: the record runs",
)
"""The per-call range warnings of the families' ``predict`` (temperature, Ṫ, time since
power-on) that one :func:`outside_range_message` per channel replaces where a whole run
or file is applied (compensate, validate): pass them to ``warnings.filterwarnings``."""

_SUFFIX = {"°C": "c", "°C/min": "c_per_min", "s": "s", "counts": "counts",
           "counts/min": "counts_per_min"}  # fmt: skip


@dataclass(frozen=True)
class RangeExcess:
    """How far one input of a model left the range it was calibrated over.

    ``quantity``: ``temperature`` [°C], ``temperature_rate`` (Ṫ [°C/min], models with rate
    terms) or ``time_since_power_on`` [s] (warm-up models: the time since the record's first
    sample against the longest fitted power-on); ``counts``/``counts/min`` for a model in raw
    counts.  A sample is outside when any checked column is below its calibrated minimum or
    above its maximum; ``beyond[col]`` is the largest distance ``max(lo − x, x − hi, 0)``
    over the samples [unit]; ``seen[col]`` the range met and ``fitted[col]`` the calibrated
    one.

    Attributes
    ----------
    quantity : str
        ``temperature``, ``temperature_rate`` or ``time_since_power_on``.
    unit : str
        [°C], [°C/min], [s], or counts.
    n_samples, n_outside : int
        Samples checked and samples outside.
    beyond : dict of str to float
        Largest distance outside per column [unit].
    seen, fitted : dict of str to tuple of float
        Range met and calibrated range per column [unit].
    """

    quantity: str
    unit: str
    n_samples: int
    n_outside: int
    beyond: dict[str, float]
    seen: dict[str, tuple[float, float]]
    fitted: dict[str, tuple[float, float]]

    @property
    def share(self) -> float:
        """Fraction of the samples outside (0…1)."""
        return self.n_outside / self.n_samples if self.n_samples else 0.0

    @property
    def max_beyond(self) -> float:
        """The largest distance outside over every column [unit]."""
        return max(self.beyond.values(), default=0.0)

    def to_dict(self) -> dict[str, Any]:
        """``share`` (0…1), ``share_pct``, ``n_outside``, ``n_samples``, ``max_beyond_<unit>``
        (``_c``, ``_c_per_min``, ``_s``), ``unit``, and per column ``seen``/``range``/``beyond``."""
        return {
            "share": self.share,
            "share_pct": 100.0 * self.share,
            "n_outside": self.n_outside,
            "n_samples": self.n_samples,
            f"max_beyond_{_SUFFIX.get(self.unit, 'value')}": self.max_beyond,
            "unit": self.unit,
            "columns": {
                c: {"seen": list(self.seen[c]), "range": list(self.fitted[c]),
                    "beyond": self.beyond[c]}
                for c in self.fitted
            },
        }  # fmt: skip

    def describe(self) -> str:
        """One phrase: share, how far, and the columns that left their range."""
        what = {"temperature": "temperature", "temperature_rate": "Ṫ",
                "time_since_power_on": "time after power-on"}[self.quantity]  # fmt: skip
        cols = ", ".join(
            f"{c} met {self.seen[c][0]:.4g}…{self.seen[c][1]:.4g} {self.unit}, calibrated "
            f"{self.fitted[c][0]:.4g}…{self.fitted[c][1]:.4g} {self.unit}"
            for c in self.fitted
            if self.beyond[c] > 0
        )
        return (
            f"{what}: {self.n_outside} samples outside ({100.0 * self.share:.3g} % of "
            f"{self.n_samples}), up to {self.max_beyond:.3g} {self.unit} beyond ({cols})"
        )


class RangeTally:
    """Accumulates, chunk by chunk, how far a run leaves a model's calibrated ranges.

    Feed the samples in order with :meth:`add` (time [s], temperatures (n, k) in the
    model's temperature unit, columns in ``temp_names_`` order); :meth:`result` gives one
    :class:`RangeExcess` per checked input.  Ṫ is the model's own (``model.rates``: its
    Δt and difference form, never across a gap) computed with the last ``2Δt`` of the
    previous chunks as history, so chunked and whole-run figures agree for the causal
    backward form; the time since power-on counts from the first sample added.

    Parameters
    ----------
    model : TemperatureModel
        A fitted model.

    Raises
    ------
    thermocal.errors.ThermocalInputError
        The model is not fitted.
    """

    def __init__(self, model: TemperatureModel) -> None:
        model.check_fitted()
        self.model = model
        self.names = tuple(model.temp_names_)
        self._lo = np.asarray(model.temp_range_, dtype=np.float64)[:, 0]
        self._hi = np.asarray(model.temp_range_, dtype=np.float64)[:, 1]
        tu = "°C" if model.temperature_unit == "degC" else model.temperature_unit
        self._tu = tu
        self.n = 0
        self._t_out = 0
        self._t_min = np.full(self._lo.size, np.inf)
        self._t_max = np.full(self._lo.size, -np.inf)
        # Ṫ: the sensors whose rate a term uses (poly), with the model's rate definition
        rr = getattr(model, "rate_range_", None)
        self._rate_cols: list[int] = []
        if rr is not None and bool(getattr(model, "model_uses_rate", False)):
            self._rate_cols = [int(j) for j in model._rate_sensors()]  # type: ignore[attr-defined]
            self._r_lo = np.asarray(rr, dtype=np.float64)[:, 0]
            self._r_hi = np.asarray(rr, dtype=np.float64)[:, 1]
            self._r_min = np.full(self._lo.size, np.inf)
            self._r_max = np.full(self._lo.size, -np.inf)
            self._r_out = 0
            self._hist_s = 2.0 * float(getattr(model, "rate_interval_s", 60.0))
            self._tail_t: FloatArray = np.zeros(0)
            self._tail_T: FloatArray = np.zeros((0, self._lo.size))
        # time since power-on: warm-up models record their fitted power-on durations
        dur = getattr(model, "duration_range_s_", None)
        self._dur: tuple[float, float] | None = (
            None if dur is None else (float(dur[0]), float(dur[1]))
        )
        self._t0: float | None = None
        self._e_max = -np.inf
        self._e_out = 0

    def add(self, time_s: FloatArray, temps_c: FloatArray) -> None:
        """The next samples of the run (in time order).

        Parameters
        ----------
        time_s : numpy.ndarray
            Sample times (n,) [s].
        temps_c : numpy.ndarray
            Temperatures (n, k) in the model's temperature unit.
        """
        t = np.asarray(time_s, dtype=np.float64).reshape(-1)
        T = np.asarray(temps_c, dtype=np.float64).reshape(t.size, -1)
        if t.size == 0:
            return
        self.n += int(t.size)
        temps = T
        out = (temps < self._lo) | (temps > self._hi)
        self._t_out += int(np.count_nonzero(out.any(axis=1)))
        self._t_min = np.minimum(self._t_min, T.min(axis=0))
        self._t_max = np.maximum(self._t_max, T.max(axis=0))
        if self._rate_cols:
            m = self._tail_t.size
            ct = np.concatenate([self._tail_t, t])
            cT = np.concatenate([self._tail_T, T])
            r = np.asarray(self.model.rates(ct, cT), dtype=np.float64)[m:]  # type: ignore[attr-defined]
            j = self._rate_cols
            rj = r[:, j]
            self._r_out += int(
                np.count_nonzero(((rj < self._r_lo[j]) | (rj > self._r_hi[j])).any(axis=1))
            )
            self._r_min[j] = np.minimum(self._r_min[j], rj.min(axis=0))
            self._r_max[j] = np.maximum(self._r_max[j], rj.max(axis=0))
            keep = ct >= ct[-1] - self._hist_s
            self._tail_t, self._tail_T = ct[keep].copy(), cT[keep].copy()
        if self._dur is not None:
            if self._t0 is None:
                self._t0 = float(t[0])
            e = t - self._t0
            self._e_max = max(self._e_max, float(e[-1]))
            self._e_out += int(np.count_nonzero(e > self._dur[1]))

    def result(self) -> tuple[RangeExcess, ...]:
        """One :class:`RangeExcess` per checked input (temperature always; Ṫ for models
        with rate terms; time since power-on for warm-up models); empty before any sample."""
        if self.n == 0:
            return ()

        def excess(
            quantity: str, unit: str, n_out: int, cols: Sequence[int],
            mn: FloatArray, mx: FloatArray, lo: FloatArray, hi: FloatArray,
        ) -> RangeExcess:  # fmt: skip
            names = [self.names[i] for i in cols]
            return RangeExcess(
                quantity=quantity,
                unit=unit,
                n_samples=self.n,
                n_outside=n_out,
                beyond={
                    n: float(max(lo[i] - mn[i], mx[i] - hi[i], 0.0))
                    for n, i in zip(names, cols, strict=True)
                },
                seen={n: (float(mn[i]), float(mx[i])) for n, i in zip(names, cols, strict=True)},
                fitted={n: (float(lo[i]), float(hi[i])) for n, i in zip(names, cols, strict=True)},
            )

        all_cols = list(range(self._lo.size))
        out = [
            excess("temperature", self._tu, self._t_out, all_cols,
                   self._t_min, self._t_max, self._lo, self._hi)
        ]  # fmt: skip
        if self._rate_cols:
            out.append(
                excess("temperature_rate", f"{self._tu}/min", self._r_out, self._rate_cols,
                       self._r_min, self._r_max, self._r_lo, self._r_hi)
            )  # fmt: skip
        if self._dur is not None:
            lo, hi = self._dur
            out.append(
                RangeExcess(
                    quantity="time_since_power_on",
                    unit="s",
                    n_samples=self.n,
                    n_outside=self._e_out,
                    beyond={"power-on": max(self._e_max - hi, 0.0)},
                    seen={"power-on": (0.0, self._e_max)},
                    fitted={"power-on": (lo, hi)},
                )
            )
        return tuple(out)


def outside_range(model: TemperatureModel, time_s: FloatArray, temps_c: FloatArray) -> tuple[
    RangeExcess, ...
]:  # fmt: skip
    """How far one whole run (time [s], temperatures (n, k)) leaves ``model``'s calibrated
    ranges (:class:`RangeTally` fed once).

    Parameters
    ----------
    model : TemperatureModel
        A fitted model.
    time_s : numpy.ndarray
        Sample times (n,) [s].
    temps_c : numpy.ndarray
        Temperatures (n, k) [°C].

    Returns
    -------
    tuple of RangeExcess
        One per checked input.

    Notes
    -----
    .. math:: \\mathrm{beyond} = \\max_i \\max(lo - x_i,\\; x_i - hi,\\; 0)
    """
    tally = RangeTally(model)
    tally.add(time_s, temps_c)
    return tally.result()


def outside_range_message(
    excess: Sequence[RangeExcess], where: str, *, extrapolate: bool
) -> str | None:
    """The one warning for a channel applied outside its calibrated range (None when every
    sample is inside): each input that left, with its share of samples and how far.

    Parameters
    ----------
    excess : sequence of RangeExcess
        From :func:`outside_range`.
    where : str
        The data's name.
    extrapolate : bool
        Wording (extrapolating or clamped).

    Returns
    -------
    str or None
    """
    bad = [e for e in excess if e.n_outside > 0]
    if not bad:
        return None
    action = (
        "the model is extrapolated there"
        if extrapolate
        else "the model's inputs are held at the calibrated range there"
    )
    return (
        f"{where}: the model is applied outside its calibrated range: "
        + "; ".join(e.describe() for e in bad)
        + f"; {action}"
    )


def outside_range_dict(excess: Sequence[RangeExcess]) -> dict[str, Any]:
    """``{quantity: RangeExcess.to_dict()}`` of every checked input (JSON ``outside_range``).

    Parameters
    ----------
    excess : sequence of RangeExcess
        From :func:`outside_range`.

    Returns
    -------
    dict
    """
    return {e.quantity: e.to_dict() for e in excess}
