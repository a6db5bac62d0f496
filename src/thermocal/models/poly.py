"""Multi-sensor polynomial model with rate and coupling terms ([Seed-RLG]).

The temperature-induced signal (bias [°/h] or [mg], or scale-factor error,
[Seed-RLG]) is

.. math::

    y = a_0 + \\sum_j a_j \\, u_{k_j}^{a} v_{k_j}^{b} w_{k_j}^{c}            (1)

with the centred and scaled base variables of every sensor k
(:mod:`thermocal.models.terms`, eq. 1): ``u = (T − c_T)/s_T`` [T in °C],
``v = (Ṫ − c_R)/s_R`` [Ṫ in °C/min], ``w = (T·Ṫ − c_W)/s_W``.  The default term
set ``seed000`` (37 coefficients for four sensors) spans exactly the seed's raw
cubic polynomial in T, Ṫ and TṪ, but the regressors are orthogonal-ish, so the
least-squares problem is solved accurately (column-equilibrated QR/SVD, the
condition number is reported).  Robust default: singular values of the
equilibrated term design (constant and offsets projected out) below ``rcond``
(1e-3) × the largest are truncated (a truncated-SVD solution; the count is
reported as ``n_truncated``, ``rank``) unless the data along them exceed
``noise_threshold`` (10) × the white-noise σ̂ — truncation relative to the
noise; a design
that is singular to 1e-11 raises :class:`~thermocal.errors.DesignError` naming
the dependent terms; ``ridge`` adds ``n·α‖γ‖²`` on the equilibrated term
coefficients.  Options: explicit term lists, ``order`` (plain polynomial in the
temperatures), stepwise selection (``select="bic"`` or ``"holdout"``), per-run
turn-on offsets as nuisance parameters (``per_run_offset``; the model's constant
is then the mean of the offsets).

Ṫ is the causal backward difference over ``rate_interval_s`` (default 60 s):
``Ṫ(t) = (T(t) − T(t_j))/(t − t_j)·60`` with ``t_j`` the first sample of the
current contiguous segment with ``t_j ≥ t − Δt`` (0 at a segment's first
sample; a step longer than 1.5 × the nominal interval starts a new segment);
see :func:`thermocal.preprocess.temperature_rate`.  ``"forward"`` and
``"centred"`` forms may be chosen for batch use (not for streaming).

Evaluation, in order, for every sample (this is what :meth:`PolyModel.predict`,
:class:`~thermocal.models.poly_stream.PolyStream` and the generated C code compute):

1. Ṫ_k from the *raw* temperatures (rule above) [°C/min];
2. clamp T_k to the fitted range ``range.temperature_c`` and Ṫ_k to
   ``range.rate_c_per_min`` (unless extrapolating; an
   :class:`~thermocal.errors.ExtrapolationWarning` is raised either way);
3. ``u_k, v_k, w_k`` by eq. (1) of :mod:`~thermocal.models.terms`, with
   ``w_k`` built from the clamped T_k·Ṫ_k;
4. ``y = constant + Σ_j coef[j] · u^t_power · v^rate_power · w^coupling_power``.

How steps 3–4 are computed (:class:`~thermocal.models.poly_types.EvalPlan`; the same
operations in :meth:`PolyModel.predict` on numpy blocks and in
:class:`~thermocal.models.poly_stream.PolyStream` on Python floats, so the two agree to the
last bit): the scales are folded into the coefficients and the pure powers of each variable
summed by Horner's rule in the centred variable, e.g. ``((a₃/s³·d + a₂/s²)·d + a₁/s)·d``
with ``d = T − c_T``; the centres of Ṫ and T·Ṫ (near 0) are folded into the coefficients and
the constant when every ``|c| ≤ s``. Mathematically the same model as eq. (1); numerically
it differs from the literal sum of the scaled terms by rounding only (~1e-16 relative).
``predict`` works in cache-sized blocks of
:data:`~thermocal.models.poly_eval.PREDICT_BLOCK_ROWS` samples, with Ṫ's partner samples
found per block by :func:`~thermocal.preprocess.backward_partners` (a slice on regular
sampling).

Model-file ``state`` layout (``"layout": "thermocal-poly-1"``), for the C export::

    {
      "layout": "thermocal-poly-1",
      "n_sensors": k,                      # temperature columns, order of "temperatures"
      "base": [                            # one entry per sensor, in column order
        {"name": "T1", "t_center": °C, "t_scale": °C,
         "rate_center": °C/min, "rate_scale": °C/min,
         "coupling_center": °C²/min, "coupling_scale": °C²/min}, ...],
      "terms": [                           # the kept terms, in coefficient order
        {"name": "T1^2", "sensor": 0,      # 0-based index into "base"/"temperatures"
         "t_power": 2, "rate_power": 0, "coupling_power": 0}, ...],
      "coef": [...],                       # coefficient of each term [signal unit]
      "constant": a0,                      # [signal unit] (mean of the per-run offsets)
      "offsets": [...],                    # per-run offsets (nuisance), run order of "data"
      "cov": [[...]],                      # covariance of [constant, coef...]
      "uses_rate": true,
      "rate": {"method": "backward", "interval_s": 60.0, "gap_factor": 1.5,
               "unit": "degC/min", "clamp": true},
      "selection": null | {"method": "bic"|"holdout", "kept": [...], "path": [...]}
    }

The ranges for step 2 are the file's ``range`` section (``temperature_c`` and
``rate_c_per_min``, keyed by temperature name, ``[lo, hi]``).  The file's
``coefficients`` list gives the same model expanded into raw monomials
``T_k^P Ṫ_k^Q`` (the seed's a0…a36 for ``seed000``), with standard errors;
those are for reading, the scaled basis above is for evaluation.

The model is in three modules: this one (the class, its parameters, state and stream),
:mod:`thermocal.models.poly_fit` (the least-squares fit, one channel or several sharing one
design) and :mod:`thermocal.models.poly_eval` (the evaluation plan, steps 1–4); the run
checks and ranges shared with the other families are in :mod:`thermocal.models.fitting`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, ClassVar, Self

import numpy as np

from thermocal.adequacy import Needs
from thermocal.errors import ModelFileError, ThermocalInputError
from thermocal.families import POLY, FamilyDeclaration
from thermocal.models.base import ChunkContext
from thermocal.models.checks import (
    boolean,
    fields,
    integer,
    key_path,
    list_of,
    matrix,
    near_range,
    number,
    same_length,
    string,
)
from thermocal.models.poly_eval import evaluate
from thermocal.models.poly_fit import fit_shared
from thermocal.models.poly_stream import PolyStream
from thermocal.models.poly_types import PolyBase
from thermocal.models.results import Coefficient
from thermocal.models.rundata import RunData
from thermocal.models.term_scaling import BaseScaling, monomial_name, raw_expansion
from thermocal.models.terms import Term, parse_terms
from thermocal.recording import GAP_FACTOR, FloatArray

MAX_TERM_POWER = 32
"""Highest power of a poly term's base variable accepted in a file (a polynomial of
higher order in one temperature is no calibration; a power of 2⁵³ would make export-c
and compensate run for ever)."""

BASE_KEYS = (
    "t_center", "t_scale", "rate_center", "rate_scale", "coupling_center", "coupling_scale"
)  # fmt: skip
"""The poly family's centre and scale of each base variable (:class:`~thermocal.models.
terms.BaseScaling`), centres at even positions."""


STATE_LAYOUT = "thermocal-poly-1"


class PolyModel(PolyBase):
    """Polynomial in T, Ṫ and TṪ of several sensors ([Seed-RLG]); see the module docstring.

    Parameters
    ----------
    terms : ``"seed000"`` (default), a comma-separated term text or a list of
        term texts (:func:`thermocal.models.terms.parse_terms`).
    order : plain polynomial T, …, T^order per sensor (instead of ``terms``).
    rate_interval_s : Δt of Ṫ [s] (default 60).
    rate_method : ``"backward"`` (causal, default), ``"forward"`` or ``"centred"``.
    select : None, ``"bic"`` or ``"holdout"`` (forward stepwise term selection).
    ridge : ridge α on the unit-RMS term columns (0 = none).
    rcond : truncation threshold of the SVD solution (relative to s_max).
    per_run_offset : one turn-on offset per run, estimated as nuisance parameters; None
        (default) when the runs overlap in temperature
        (:func:`~thermocal.models.fitting.decide_run_offsets`).
    solver : ``"auto"`` (Gram when well conditioned, else chunked QR), ``"qr"``, ``"gram"``.
    noise_threshold : a component below ``rcond`` is kept when ``|uᵢᵀz| > k σ̂`` (None: never).

    Notes
    -----
    For temperature sensors :math:`k` with temperature :math:`T_k` and rate
    :math:`\\dot T_k` (the backward difference over ``rate_interval_s``), the model is
    a constant plus the chosen terms, fitted by least squares:

    .. math::

        \\hat y = c_0 + \\sum_k \\sum_{p} a_{kp} T_k^p + b_{kp} \\dot T_k^p
                 + d_{kp} (T_k \\dot T_k)^p

    and the compensated output is :math:`F' = F - \\hat y`.

    References
    ----------
    .. [1] *A modelling and validation method for the temperature compensation model of a
       ring-laser gyroscope*, Chinese invention patent, 2017 (docs/methods.md,
       Seed-RLG).
    .. [2] IEEE Std 952-1997, *IEEE Standard Specification Format Guide and Test Procedure
       for Single-Axis Interferometric Fiber Optic Gyros* (the temperature-sensitivity
       terms of the model equation).

    Examples
    --------
    >>> import numpy as np
    >>> from thermocal.models import RunData
    >>> from thermocal.models.poly import PolyModel
    >>> t = np.arange(0.0, 3600.0, 10.0)
    >>> temp = 25.0 + 15.0 * np.sin(2 * np.pi * t / 3600.0)
    >>> run = RunData(t, temp[:, None], 0.5 + 0.02 * temp, ("T1",))
    >>> model = PolyModel(order=1).fit([run])
    >>> [(c.name, round(c.value, 4)) for c in model.coefficients()]
    [('const', 0.5), ('T1', 0.02)]
    >>> round(float(model.predict(run)[0]), 4)
    1.0
    """

    declaration: ClassVar[FamilyDeclaration] = POLY
    uses_rate: ClassVar[bool] = True

    # -- construction from the command line --

    def chunk_context(self) -> ChunkContext:
        """Eq. (1) needs the last Δt seconds (the Ṫ interval) and nothing of the start."""
        return ChunkContext(head_s=0.0, tail_s=float(self.rate_interval_s))

    # -- estimator contract --
    def fit(self, runs: Sequence[RunData]) -> Self:
        """Least-squares fit of eq. (1) on one or several runs; returns ``self``.

        Works through each run in blocks of :data:`~thermocal.models.terms.CHUNK_ROWS`
        samples (Ṫ, features and the reduction per block), so memory stays at the
        input arrays plus a few MB.  :func:`~thermocal.models.poly_fit.fit_shared` fits
        several channels at once.

        Parameters
        ----------
        runs : sequence of RunData
            Runs with times [s], temperatures [°C] and signal [°/h or mg].

        Returns
        -------
        PolyModel
            ``self``, fitted.

        Raises
        ------
        thermocal.errors.DesignError
            The data cannot determine the model (rank, ranges, segments).
        """
        fit_shared([self], [runs])
        return self

    def data_needs(self, temp_names: Sequence[str], n_runs: int) -> Needs:
        """Order in T per column (T and T·Ṫ powers), the terms plus the constant and the
        per-run offsets, and the columns with Ṫ terms.

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
        terms = parse_terms(self.terms, len(temp_names), self.order)
        order = {n: 0 for n in temp_names}
        for t in terms:
            n = temp_names[t.sensor]
            order[n] = max(order[n], t.t_power + t.coupling_power)
        rate = tuple(temp_names[s] for s in sorted({t.sensor for t in terms if t.uses_rate}))
        offsets = n_runs - 1 if (self.per_run_offset is not False and n_runs > 1) else 0
        return Needs(order, len(terms) + 1 + offsets, rate)

    @property
    def model_uses_rate(self) -> bool:
        """True when a fitted term uses Ṫ."""
        return any(t.uses_rate for t in self.terms_)

    def _rate_sensors(self) -> list[int]:
        return sorted({t.sensor for t in self.terms_ if t.uses_rate})

    def predict(self, run: RunData, *, extrapolate: bool = False) -> FloatArray:
        """Temperature-induced signal of every sample [signal unit] (module docstring steps 1–4).

        Evaluated in blocks of :data:`~thermocal.models.poly_eval.PREDICT_BLOCK_ROWS` rows
        (Ṫ partners found per block by :func:`~thermocal.preprocess.backward_partners`;
        Horner's rule per sensor, :class:`~thermocal.models.poly_types.EvalPlan`); the same
        numbers as :class:`~thermocal.models.poly_stream.PolyStream`.

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
        return evaluate([self], run, extrapolate=extrapolate)[0]

    def stream(self, sample_interval_s: float, *, extrapolate: bool = False) -> PolyStream:
        """Sample-by-sample twin of :meth:`predict` (needs the backward rate form).

        Parameters
        ----------
        sample_interval_s : float
            Nominal sample interval [s].
        extrapolate : bool, optional
            Default False.

        Returns
        -------
        PolyStream
        """
        self.check_fitted()
        if self.model_uses_rate and self.rate_method != "backward":
            raise ThermocalInputError(
                "streaming needs the causal 'backward' rate form; this model uses "
                f"{self.rate_method!r}"
            )
        return PolyStream(self, sample_interval_s, extrapolate=extrapolate)

    def coefficients(self) -> list[Coefficient]:
        """Raw-monomial coefficients ``a`` of ``T_k^P Ṫ_k^Q`` with standard errors (seed form)."""
        self.check_fitted()
        keys, M = raw_expansion(self.terms_, self.scaling_)
        beta = np.r_[self.constant_, self.coef_]
        raw = M @ beta
        cov = M @ self.cov_ @ M.T
        se = np.sqrt(np.clip(np.diag(cov), 0.0, None))
        out: list[Coefficient] = []
        for key, v, s in zip(keys, raw, se, strict=True):
            _k, P, Q = key
            unit = _monomial_unit(self.signal_unit, P, Q)
            out.append(
                Coefficient(
                    name=monomial_name(key),
                    value=float(v),
                    stderr=float(s) if math.isfinite(s) else None,
                    unit=unit,
                )
            )
        return out

    def coefficients_about(self, tref_c: float) -> list[Coefficient]:
        """Raw-monomial coefficients about a reference temperature: the same model written
        in ``dT_k = T_k − TREF`` (the convention of PX4's and ArduPilot's thermal
        calibrations, ``thermocal export-params``), with standard errors.

        Each monomial ``T_k^P Ṫ_k^Q = ((T_k − TREF) + TREF)^P Ṫ_k^Q`` expands binomially
        into ``Σ_j C(P, j) TREF^(P−j) dT_k^j Ṫ_k^Q``; with ``S`` that linear map,
        ``b = S a`` and ``cov b = S cov a Sᵀ``.  Names use ``dT1`` for ``T1 − TREF``…
        (rates keep ``Ṫ``, written ``rate1``).  Only the constant and the
        polynomial terms change; the model's values do not.

        Parameters
        ----------
        tref_c : float
            Reference temperature TREF [°C].

        Returns
        -------
        list of Coefficient

        Notes
        -----
        .. math:: T^P = \\sum_{j=0}^{P} \\binom{P}{j} T_\\mathrm{ref}^{P-j} (T - T_\\mathrm{ref})^j,
                  \\qquad \\mathrm{cov}\\, b = S\\, \\mathrm{cov}\\, a\\, S^\\top

        References
        ----------
        - PX4 ``Tools/process_sensor_caldata.py`` and ArduPilot
          ``AP_InertialSensor_tempcal.cpp`` (polynomials in T − TREF).
        """
        self.check_fitted()
        if not math.isfinite(tref_c):
            raise ThermocalInputError(f"TREF must be a finite temperature, got {tref_c}")
        keys, M = raw_expansion(self.terms_, self.scaling_)
        beta = np.r_[self.constant_, self.coef_]
        raw = M @ beta
        cov_raw = M @ self.cov_ @ M.T
        out_keys: list[tuple[int, int, int]] = [(-1, 0, 0)]
        index = {(-1, 0, 0): 0}
        entries: list[tuple[int, int, float]] = []  # (row in b, column in a, weight)
        for col, (k, P, Q) in enumerate(keys):
            if k < 0:
                entries.append((0, col, 1.0))
                continue
            for j in range(P + 1):
                new = (k, j, Q) if (j or Q) else (-1, 0, 0)
                if new not in index:
                    index[new] = len(out_keys)
                    out_keys.append(new)
                entries.append((index[new], col, math.comb(P, j) * tref_c ** (P - j)))
        S = np.zeros((len(out_keys), len(keys)))
        for row, col, w in entries:
            S[row, col] += w
        b = S @ raw
        se = np.sqrt(np.clip(np.diag(S @ cov_raw @ S.T), 0.0, None))
        out: list[Coefficient] = []
        for key, v, e in zip(out_keys, b, se, strict=True):
            k, P, Q = key
            unit = _monomial_unit(self.signal_unit, P, Q)
            name = "const"
            if k >= 0:
                parts = []
                if P:
                    parts.append(f"(T{k + 1}-TREF)" + (f"^{P}" if P > 1 else ""))
                if Q:
                    parts.append(f"rate{k + 1}" + (f"^{Q}" if Q > 1 else ""))
                name = "*".join(parts)
            out.append(Coefficient(name, float(v), float(e) if math.isfinite(e) else None, unit))
        return out

    @classmethod
    def check_state(cls, d: dict[str, Any], root: str = "") -> None:
        """The ``state`` section of a poly model file (:meth:`_state`'s layout): centres and
        scales per base variable (scales not 0), terms of powers 0…:data:`MAX_TERM_POWER` on
        known sensors, one coefficient per term; a used centre in or near its fitted range.

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
        state, path, n_temps = d["state"], key_path(root, "state"), len(d["temperatures"])
        fields(
            {
                "layout": string,
                "base": list_of(fields({k: number for k in BASE_KEYS}), min_len=1),
                "terms": list_of(
                    fields({"sensor": integer, "t_power": integer, "rate_power": integer,
                            "coupling_power": integer})
                ),
                "coef": list_of(number),
                "constant": number,
            },
            optional={"offsets": list_of(number), "cov": matrix, "uses_rate": boolean,
                      "n_sensors": integer},
        )(state, path)  # fmt: skip
        same_length(state, path, "coef", len(state["terms"]), "one per term")
        for i, base in enumerate(state["base"]):
            for key in BASE_KEYS[1::2]:
                if base[key] == 0:
                    raise ModelFileError(f"{path}.base[{i}].{key}: must not be 0")
        for i, term in enumerate(state["terms"]):
            for key in ("t_power", "rate_power", "coupling_power"):
                if not 0 <= term[key] <= MAX_TERM_POWER:
                    raise ModelFileError(
                        f"{path}.terms[{i}].{key}: {term[key]} is not a power 0…{MAX_TERM_POWER}"
                    )
            if not 0 <= term["sensor"] < len(state["base"]):
                raise ModelFileError(
                    f"{path}.terms[{i}].sensor: {term['sensor']} is not one of the "
                    f"{len(state['base'])} temperature inputs"
                )
        if len(state["base"]) > n_temps:
            raise ModelFileError(
                f"{path}.base: {len(state['base'])} temperature inputs but the file names {n_temps}"
            )
        ranges, temps = d["range"]["temperature_c"], d["temperatures"]
        used = {t["sensor"] for t in state["terms"] if t["t_power"] or t["coupling_power"]}
        for k in sorted(used):
            lo, hi = ranges[temps[k]]
            center = state["base"][k]["t_center"]
            near_range(center, lo, hi, key_path(root, f"state.base[{k}].t_center"), "the centre")

    # -- state --
    def _state(self) -> dict[str, Any]:
        return {
            "layout": STATE_LAYOUT,
            "n_sensors": int(self.scaling_.t_center.size),
            "base": self.scaling_.to_list(self.temp_names_ if hasattr(self, "temp_names_") else ()),
            "terms": [t.to_dict() for t in self.terms_],
            "coef": [float(c) for c in self.coef_],
            "constant": float(self.constant_),
            "offsets": [float(o) for o in self.offsets_],
            "cov": self.cov_.tolist(),
            "uses_rate": self.model_uses_rate,
            "rate": {
                "method": self.rate_method,
                "interval_s": float(self.rate_interval_s),
                "gap_factor": GAP_FACTOR,
                "unit": "degC/min",
                "clamp": True,
            },
            "selection": self.selection_,
        }

    def _set_state(self, state: dict[str, Any]) -> None:
        if state.get("layout") != STATE_LAYOUT:
            raise ThermocalInputError(
                f"poly model state layout {state.get('layout')!r} is not {STATE_LAYOUT!r}"
            )
        self.scaling_ = BaseScaling.from_list(state["base"])
        self.terms_ = [Term.from_dict(t) for t in state["terms"]]
        self.coef_ = np.asarray(state["coef"], dtype=np.float64)
        self.constant_ = float(state["constant"])
        self.offsets_ = np.asarray(state.get("offsets", []), dtype=np.float64)
        self.cov_ = np.asarray(state["cov"], dtype=np.float64)
        self.selection_ = state.get("selection")
        if self.coef_.size != len(self.terms_):
            raise ThermocalInputError("poly model state: coefficient and term counts differ")

    def to_dict(self) -> dict[str, Any]:
        """The model file's content (without checksum); ``rate`` is null when no term uses Ṫ."""
        d = super().to_dict()
        if not self.model_uses_rate:
            d["rate"] = None
        return d


def _monomial_unit(signal_unit: str, P: int, Q: int) -> str:
    """Unit of the coefficient of ``T^P Ṫ^Q``: ``signal/degC^P/(degC/min)^Q``."""
    unit = signal_unit
    if P:
        unit += "/degC" + (f"^{P}" if P > 1 else "")
    if Q:
        unit += "/(degC/min)" + (f"^{Q}" if Q > 1 else "")
    return unit
