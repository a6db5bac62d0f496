"""The declarations of the model families, free of numpy.

A model family is a class of :mod:`thermocal.models` (the maths); what the rest of thermocal
asks of it — its name, its fit options with their bounds and help texts, what it needs of
the data, whether firmware can run it — is a :class:`FamilyDeclaration` the class carries as
``declaration``.  The declarations of the built-in families live here so that
the ``fit`` command's help can show every option without importing numpy; the class points to
its declaration, and :data:`BUILTIN_FAMILIES` is the one registration line of each built-in
family (:mod:`thermocal.models.registry` imports the classes from it).  A family from
another package declares itself on its class and registers through the entry-point group
:data:`ENTRY_POINT_GROUP`.

Examples
--------
>>> from thermocal.families import BUILTIN_FAMILIES, MODEL_FAMILIES
>>> MODEL_FAMILIES
('poly', 'piecewise', 'warmup', 'bank', 'hyst')
>>> order = next(o for o in BUILTIN_FAMILIES[0].options if o.name == "order")
>>> order.check(3), order.kind
(3, 'int')
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Final, Literal

from thermocal.errors import ParameterError

OptionKind = Literal["int", "float", "str", "bool", "floats"]
"""How an option's value is typed: an integer, a float, a name, a yes/no, a tuple of floats."""

ENTRY_POINT_GROUP: Final = "thermocal.families"
"""The entry-point group of model families from other packages (``name = "pkg.mod:Class"``)."""

MAX_ORDER: Final = 10
"""Hard ceiling of a temperature polynomial's order (poly: powers of each temperature;
warmup: order in ΔT and in T0).  A polynomial of order 10 over a −40…85 °C range already has a
condition number near 1e9 on scaled variables (each further power loses about one digit of
the fit's 16); calibration practice (IEEE Std 952-1997, IEEE Std 1293-1998, the PX4 and
ArduPilot thermal calibrations: order 3) stays well below.  Checked before any data is read,
so that an order of 10²⁰ never becomes a list of 10²⁰ terms."""

MAX_TERMS: Final = 200
"""Hard ceiling of the number of terms of a poly model: a design of 200 float64 columns
costs 1.6 kB per sample (16 GB at 10⁷ samples)."""

MAX_SEGMENTS: Final = 100
"""Hard ceiling of a piecewise model's segments: 100 segments over −40…85 °C are 1.25 °C
each, below which a segment fits the noise of one soak rather than a temperature effect."""


def _shown(value: object) -> str:
    """A value as an error shows it (an integer of hundreds of digits cut short)."""
    text = str(value)
    return text if len(text) <= 24 else f"{text[:20]}… ({len(text)} digits)"


@dataclass(frozen=True)
class FamilyOption:
    """One fit option of a model family: a parameter of the family's constructor.

    Parameters
    ----------
    name : str
        The constructor parameter (``"rate_interval_s"``).
    kind : {"int", "float", "str", "bool", "floats"}
        The value's type (``"floats"``: a tuple of floats, e.g. breakpoints [°C]).
    help : str
        One line for the command line's help, with the unit in brackets.
    lo, hi : float, optional
        Bounds of a number (inclusive); ``lo_open``: ``lo`` itself is refused.  A float
        option must be finite.
    choices : tuple of str
        The values a ``"str"`` option takes (empty: any).
    option : str, optional
        The command line's name without dashes, when it is not ``name``
        (``rate_interval_s`` → ``rate_interval``, shown with dashes).
    switch : str, optional
        A choice given on the command line as a flag (``NAME``) with a second option
        (``SWITCH``) choosing the value (``select`` with ``select_method`` ``holdout``); the
        first choice is the default.
    """

    name: str
    kind: OptionKind
    help: str
    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    choices: tuple[str, ...] = ()
    option: str | None = None
    switch: str | None = None

    @property
    def field(self) -> str:
        """The command line's name of the option without dashes, underscores kept."""
        return self.option or self.name

    @property
    def cli(self) -> str:
        """The option of the ``fit`` command: :attr:`field` with dashes, two in front."""
        return "--" + self.field.replace("_", "-")

    def check(self, value: Any) -> Any:
        """``value`` checked against the option's type and bounds, as the constructor takes
        it (a tuple of floats for ``"floats"``).

        Parameters
        ----------
        value : object
            The value given.

        Returns
        -------
        object
            The value as the constructor takes it.

        Raises
        ------
        thermocal.errors.ParameterError
            Naming :attr:`name`, when the value is of the wrong type or out of bounds.
        """
        if self.kind == "bool":
            if not isinstance(value, bool):
                raise ParameterError(self.name, f"{{name}} must be true or false, got {value!r}")
            return value
        if self.kind == "str":
            if not isinstance(value, str) or (self.choices and value not in self.choices):
                c = self.choices
                allowed = (", ".join(c[:-1]) + " or " + c[-1]) if c else "a name"
                raise ParameterError(self.name, f"{{name}} must be {allowed}, got {value!r}")
            return value
        if self.kind == "floats":
            return self._check_floats(value)
        return self._check_number(value)

    def _check_floats(self, value: Any) -> tuple[float, ...]:
        """A tuple of finite floats, at least one."""
        try:
            out = tuple(float(v) for v in value)
        except (TypeError, ValueError):
            raise ParameterError(self.name, f"{{name}} must be numbers, got {value!r}") from None
        if not out:
            raise ParameterError(self.name, "{name} holds no number")
        return out

    def _check_number(self, value: Any) -> int | float:
        """An integer or a finite float within the bounds."""
        integer = self.kind == "int"
        if isinstance(value, bool) or not isinstance(value, int if integer else int | float):
            what = "an integer" if integer else "a number"
            raise ParameterError(self.name, f"{{name}} must be {what}, got {value!r}")
        if not integer and not math.isfinite(value):
            raise ParameterError(self.name, f"{{name}} must be a finite number, got {value}")
        low = self.lo is not None and (value <= self.lo if self.lo_open else value < self.lo)
        high = self.hi is not None and value > self.hi
        if low or high:
            if self.lo is not None and self.hi is not None:
                rule = f"between {self.lo:g} and {self.hi:g}"
            elif self.lo is not None:
                rule = f"{'>' if self.lo_open else '≥'} {self.lo:g}"
            else:
                rule = f"≤ {self.hi:g}"
            raise ParameterError(self.name, f"{{name}} must be {rule}, got {_shown(value)}")
        return value if integer else float(value)


@dataclass(frozen=True)
class FamilyDeclaration:
    """What a model family declares of itself.

    Parameters
    ----------
    name : str
        The family's name (the ``model`` of a fit, the model file's ``family``).
    model_class : str
        Where the class is, ``"module:Class"`` (imported only when the family is used).
    summary : str
        One line for the help.
    options : tuple of FamilyOption
        The fit options (constructor parameters) the command line and fleet
        configurations give; the constructor may take more (library only).
    data_needs : str
        What the family asks of the data, in words (the numbers come from the fitted
        object's ``data_needs``).
    c_generator : str, optional
        The module of :mod:`thermocal.export.c` writing the family's C code (None: none).
    firmware : tuple of str
        Flight-controller parameter formats the family's coefficients fill
        (``"px4"``, ``"ardupilot"``); empty: none.
    """

    name: str
    model_class: str
    summary: str
    options: tuple[FamilyOption, ...]
    data_needs: str
    c_generator: str | None = None
    firmware: tuple[str, ...] = ()

    def option(self, name: str) -> FamilyOption:
        """The declared option of constructor parameter ``name`` (KeyError when none).

        Parameters
        ----------
        name : str
            Constructor parameter.

        Returns
        -------
        FamilyOption
        """
        for o in self.options:
            if o.name == name:
                return o
        raise KeyError(name)


_ORDER = "T, …, T^order per temperature, instead of --terms"  # cli-words: the command's help
_PER_RUN = "one turn-on offset per run (nuisance parameters)"

POLY: Final = FamilyDeclaration(
    "poly",
    "thermocal.models.poly:PolyModel",
    "polynomial in T, Ṫ and T·Ṫ of one or several temperature sensors",
    (
        FamilyOption("terms", "str", '"seed000" or "T1,T1^2,dT1,T1*dT1,..."'),
        FamilyOption("order", "int", f"plain polynomial order ({_ORDER})", 1, MAX_ORDER),
        FamilyOption(
            "rate_interval_s",
            "float",
            "Δt of Ṫ [s] (default 60)",
            0.0,
            lo_open=True,
            option="rate_interval",
        ),
        FamilyOption(
            "rate_method",
            "str",
            "backward | forward | centred",
            choices=("backward", "forward", "centred"),
        ),
        FamilyOption(
            "select",
            "str",
            "stepwise term selection, criterion bic | holdout",
            choices=("bic", "holdout"),
            switch="select_method",
        ),
        FamilyOption("ridge", "float", "ridge α on the unit-RMS term columns"),
        FamilyOption("rcond", "float", "SVD truncation (default 1e-3)", 0.0),
        FamilyOption("per_run_offset", "bool", _PER_RUN),
        FamilyOption("solver", "str", "auto | qr | gram", choices=("auto", "qr", "gram")),
        FamilyOption(
            "noise_threshold", "float", "keep truncated SVD components above K σ (default 10)", 0.0
        ),
    ),
    "the polynomial's order in each temperature column, one coefficient a term plus the "
    "constant and the per-run offsets, Ṫ where a term uses it",
    "thermocal.export.c.poly",
    ("px4", "ardupilot"),
)
"""``poly``: :class:`thermocal.models.poly.PolyModel`."""

PIECEWISE: Final = FamilyDeclaration(
    "piecewise",
    "thermocal.models.piecewise:PiecewiseModel",
    "piecewise-linear in one temperature, breakpoints given or chosen from the data",
    (
        FamilyOption("breakpoints", "floats", "breakpoints [°C], e.g. 25,30"),
        FamilyOption("segments", "int", "N segments chosen from the data", 1, MAX_SEGMENTS),
        FamilyOption(
            "method", "str", "intersect | continuous", choices=("intersect", "continuous")
        ),
        FamilyOption("per_run_offset", "bool", _PER_RUN),
    ),
    "a line in its temperature column, S + 1 coefficients and the per-run offsets; each "
    "segment judged after the fit",
    "thermocal.export.c.piecewise",
)
"""``piecewise``: :class:`thermocal.models.piecewise.PiecewiseModel`."""

WARMUP: Final = FamilyDeclaration(
    "warmup",
    "thermocal.models.warmup:WarmupModel",
    "warm-up drift: polynomial in ΔT = T − T0 whose coefficients depend on T0",
    (
        FamilyOption("order", "int", "order in ΔT", 1, MAX_ORDER),
        FamilyOption("t0_order", "int", "coefficient order in T0", 0, MAX_ORDER),
        FamilyOption(
            "start_window_s", "float", "F0/T0 window [s]", 0.0, lo_open=True, option="start_window"
        ),
        FamilyOption("method", "str", "two_stage | joint", choices=("two_stage", "joint")),
        FamilyOption("per_run_offset", "bool", _PER_RUN),
    ),
    "a line in its temperature column, (order + 1)(t0_order + 1) coefficients, several "
    "power-ons at different start temperatures",
    "thermocal.export.c.warmup",
)
"""``warmup``: :class:`thermocal.models.warmup.WarmupModel`."""

BANK: Final = FamilyDeclaration(
    "bank",
    "thermocal.models.bank:BankModel",
    "a bank of piecewise-linear curves, one chosen at power-on from the start-up",
    (
        FamilyOption(
            "deviation", "float", "distinct-curve threshold [signal unit]", 0.0, lo_open=True
        ),
        FamilyOption(
            "tolerance", "float", "model acceptance tolerance [signal unit]", 0.0, lo_open=True
        ),
        FamilyOption("startup_s", "float", "start-up window [s]", 0.0, lo_open=True),
    ),
    "each curve a line in its temperature column; several power-ons",
    "thermocal.export.c.bank",
)
"""``bank``: :class:`thermocal.models.bank.BankModel`."""

HYST: Final = FamilyDeclaration(
    "hyst",
    "thermocal.models.hyst:HystModel",
    "thermal hysteresis: polynomial in the die temperature, a first-order lag τ of T",
    (
        FamilyOption("order", "int", "order in the lagged temperature", 1, MAX_ORDER),
        FamilyOption(
            "tau_s", "float", "the lag τ held fixed [s] (default: fitted)", 0.0, option="tau"
        ),
        FamilyOption(
            "tau_max_s",
            "float",
            "upper bound of the lag search [s] (default half the record)",
            0.0,
            lo_open=True,
            option="tau_max",
        ),
    ),
    "the polynomial's order in its temperature column and the lag τ; a record that heats "
    "and cools (or changes rate) to tell τ apart",
    "thermocal.export.c.hyst",
)
"""``hyst``: :class:`thermocal.models.hyst.HystModel`."""

BUILTIN_FAMILIES: Final = (POLY, PIECEWISE, WARMUP, BANK, HYST)
"""The built-in families, one registration each, in the order the ``fit`` command's help
lists them."""

MODEL_FAMILIES: Final = tuple(f.name for f in BUILTIN_FAMILIES)
"""The built-in families' names."""


def fit_option_table(
    declarations: tuple[FamilyDeclaration, ...] = BUILTIN_FAMILIES,
) -> dict[str, list[tuple[str, FamilyOption]]]:
    """Every fit option of ``declarations`` by command-line field (``rate_interval``), with
    the families declaring it: ``{field: [(family, option), ...]}``, in declaration order.
    The command line makes one option of each field; its help names each family's meaning.

    Parameters
    ----------
    declarations : tuple of FamilyDeclaration, optional
        Default :data:`BUILTIN_FAMILIES`.

    Returns
    -------
    dict of str to list of tuple

    Examples
    --------
    >>> list(fit_option_table())[:4]
    ['terms', 'order', 'rate_interval', 'rate_method']
    """
    table: dict[str, list[tuple[str, FamilyOption]]] = {}
    for decl in declarations:
        for o in decl.options:
            table.setdefault(o.field, []).append((decl.name, o))
    return table


__all__ = [
    "BANK",
    "BUILTIN_FAMILIES",
    "ENTRY_POINT_GROUP",
    "HYST",
    "MAX_ORDER",
    "MAX_SEGMENTS",
    "MAX_TERMS",
    "MODEL_FAMILIES",
    "PIECEWISE",
    "POLY",
    "WARMUP",
    "FamilyDeclaration",
    "FamilyOption",
    "fit_option_table",
]
