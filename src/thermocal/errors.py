"""Exceptions and warnings of thermocal.

Every problem with the user's input is a :class:`ThermocalInputError` (or a
subclass) whose message names the file, column or row at fault.  The command line
turns these into exit status 2 and a one-line ``error: ...`` on stderr (the common rules
of the command line); anything else is an internal failure, exit status 1.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Any, Self


class ThermocalError(Exception):
    """Base class of thermocal's own exceptions."""


def spell_parameters(
    template: str, parameters: Iterable[str], spell: Callable[[str], str] | None = None
) -> str:
    """``template`` with each ``{parameter}`` written as ``spell(parameter)``.

    The library names its parameters (``rate_hz``); the command line names its options
    (``--rate``).  A message that names a parameter is kept as a template, and each reader
    spells the names its own way.

    Parameters
    ----------
    template : str
        The text, with ``{parameter}`` where a parameter's name goes.
    parameters : iterable of str
        The parameters the text names; other braces are left as they are.
    spell : callable, optional
        What to show for a parameter (its own name without it).

    Returns
    -------
    str

    Examples
    --------
    >>> spell_parameters("give {rate_hz} [Hz]", ["rate_hz"])
    'give rate_hz [Hz]'
    >>> spell_parameters("give {rate_hz} [Hz]", ["rate_hz"], lambda p: "--rate")
    'give --rate [Hz]'
    """
    text = template
    for p in parameters:
        text = text.replace("{" + p + "}", spell(p) if spell is not None else p)
    return text


class NamesParameters:
    """A message that names parameters of the library: kept as a template, so that the
    command line can show its options where the library shows its parameters.

    Build one with :meth:`naming`; ``str()`` of it names the parameters, :meth:`spelled`
    the way a caller chooses (the command line: its options).

    Attributes
    ----------
    template : str or None
        The message with ``{parameter}`` placeholders (None: a plain message).
    parameters : tuple of str
        The parameters named in ``template``.
    """

    template: str | None = None
    parameters: tuple[str, ...] = ()

    @classmethod
    def naming(cls, template: str, *parameters: str) -> Self:
        """The exception or warning whose message is ``template`` with ``parameters`` named.

        Parameters
        ----------
        template : str
            The message, with ``{parameter}`` for each of ``parameters``.
        *parameters : str
            The library's parameter names (``"rate_hz"``, ``"time_unit"``).

        Returns
        -------
        instance of the class
            Its ``str()`` shows the parameters' own names.

        Examples
        --------
        >>> err = ThermocalInputError.naming("time unit not stated: give {time_unit}", "time_unit")
        >>> str(err)
        'time unit not stated: give time_unit'
        >>> err.spelled(lambda p: "--time-unit")
        'time unit not stated: give --time-unit'
        """
        obj = cls(spell_parameters(template, parameters))  # type: ignore[call-arg]
        obj.template = template
        obj.parameters = tuple(parameters)
        return obj

    @classmethod
    def around(
        cls, exc: BaseException, before: str = "", after: str = "", *parameters: str
    ) -> Self:
        """``exc``'s message between ``before`` and ``after``, still naming the parameters
        that ``exc`` names (a message passed up with the file it concerns put in front).

        Parameters
        ----------
        exc : BaseException
            The exception whose message is kept.
        before, after : str
            Text put before and after it, with ``{parameter}`` for each of ``parameters``.
        *parameters : str
            The parameters ``before`` and ``after`` name.

        Returns
        -------
        instance of the class

        Examples
        --------
        >>> inner = ThermocalInputError.naming("lower {static_s}", "static_s")
        >>> outer = DesignError.around(inner, "a.csv: ", "; or {poses}", "poses")
        >>> str(outer), outer.spelled(lambda p: "--" + p.replace("_", "-"))
        ('a.csv: lower static_s; or poses', 'a.csv: lower --static-s; or --poses')
        """
        if isinstance(exc, ParameterError):
            text = exc.template.replace("{name}", "{" + exc.parameter + "}")
            named: tuple[str, ...] = (exc.parameter, *exc.others)
        elif isinstance(exc, NamesParameters) and exc.template is not None:
            text, named = exc.template, exc.parameters
        else:
            text, named = str(exc), ()
        return cls.naming(before + text + after, *named, *parameters)

    def spelled(self, spell: Callable[[str], str]) -> str:
        """The message with ``spell(parameter)`` for each named parameter.

        Parameters
        ----------
        spell : callable
            What to show for a parameter (the command line: its option).

        Returns
        -------
        str
            The message (``str(self)`` when it names no parameter).
        """
        if self.template is None:
            return str(self)
        return spell_parameters(self.template, self.parameters, spell)


def _rebuild(cls: type[Any], args: tuple[Any, ...], state: dict[str, Any]) -> Any:
    """Unpickle a thermocal exception or warning with its template (the fleet's workers)."""
    obj = cls(*args)
    obj.__dict__.update(state)
    return obj


class ThermocalInputError(NamesParameters, ThermocalError, ValueError):
    """Bad input: a file, column, value, option or unit the user supplied is wrong.

    A message that names parameters of the library is built with :meth:`naming`."""

    def __reduce__(self) -> tuple[Any, ...]:
        # picklable with its template across processes (the fleet's workers)
        return (_rebuild, (type(self), self.args, dict(self.__dict__)))


class ParameterError(ThermocalInputError):
    """A bad value of one parameter of a library call.

    The message names the parameter as the library spells it (``rate_hz``); the command
    line shows the same message with its option in that place (``--rate``), through
    :meth:`named`.  Write ``{name}`` in ``message`` where the name goes.

    Parameters
    ----------
    parameter : str
        The keyword or field name, as in the signature (``"rate_hz"``).
    message : str
        The message with ``{name}`` where the parameter's name goes, e.g.
        ``"{name} must be a positive rate [Hz], got 0"``.
    others : tuple of str, optional
        Other parameters the message names, each written ``{parameter}`` in ``message``
        (``"{name} applies with {gravity_axis} only"``); shown as their own names, or as
        the options :meth:`named` is given a mapping for.

    Examples
    --------
    >>> err = ParameterError("rate_hz", "{name} must be positive, got -1")
    >>> str(err)
    'rate_hz must be positive, got -1'
    >>> err.named("--rate")
    '--rate must be positive, got -1'
    >>> msg = "{name} applies with {gravity_axis} only"
    >>> two = ParameterError("gravity", msg, ("gravity_axis",))
    >>> str(two)
    'gravity applies with gravity_axis only'
    >>> two.named("--gravity", lambda p: "--" + p.replace("_", "-"))
    '--gravity applies with --gravity-axis only'
    """

    template: str

    def __init__(self, parameter: str, message: str, others: tuple[str, ...] = ()) -> None:
        self.parameter = parameter
        self.template = message
        self.others = tuple(others)
        super().__init__(self.named(parameter))

    def named(self, name: str, other: Callable[[str], str] | None = None) -> str:
        """The message with ``name`` (an option, ``--rate``) for the parameter.

        Parameters
        ----------
        name : str
            What to show for the parameter (``--rate``).
        other : callable, optional
            What to show for each of :attr:`others` (``other(p)``; their own names
            without it).

        Returns
        -------
        str
        """
        text = self.template.replace("{name}", name)
        for p in self.others:
            text = text.replace("{" + p + "}", other(p) if other is not None else p)
        return text

    def spelled(self, spell: Callable[[str], str]) -> str:
        """The message with ``spell(p)`` for the parameter and each of :attr:`others`.

        Parameters
        ----------
        spell : callable
            What to show for a parameter (the command line: its option).

        Returns
        -------
        str
        """
        return self.named(spell(self.parameter), spell)

    def __reduce__(self) -> tuple[type[ParameterError], tuple[str, str, tuple[str, ...]]]:
        # picklable across processes (the fleet's workers)
        return (type(self), (self.parameter, self.template, self.others))


class FileFormatError(ThermocalInputError):
    """The file is not a readable CSV or Parquet file, or is empty."""


class MissingColumnError(ThermocalInputError):
    """A named column does not exist in the file."""


class NonNumericError(ThermocalInputError):
    """A cell that must hold a number does not."""


class TimestampError(ThermocalInputError):
    """Duplicate, backwards or non-finite timestamps."""


class MissingValueError(ThermocalInputError):
    """NaN or empty cells where a value is required."""


class UnitError(ThermocalInputError):
    """Unknown or inconsistent unit string."""


class ModelFileError(ThermocalInputError):
    """A model file that cannot be loaded: unknown family, newer format, corrupted."""


class DesignError(ThermocalInputError):
    """A regression or estimation problem that the data cannot determine (singular design)."""


class ThermocalWarning(NamesParameters, UserWarning):
    """Base class of thermocal's warnings.

    A warning that names parameters of the library is built with :meth:`naming`
    (``warnings.warn(UnitWarning.naming("… give {time_unit}", "time_unit"))``)."""

    def __reduce__(self) -> tuple[Any, ...]:
        return (_rebuild, (type(self), self.args, dict(self.__dict__)))


class GapWarning(ThermocalWarning):
    """The recording has gaps in time; they are reported, never interpolated."""


class TimestampWarning(ThermocalWarning):
    """The time column's steps jitter (host timestamps): ``--rate`` takes the nominal rate."""


class ExtrapolationWarning(ThermocalWarning):
    """A model is evaluated outside the temperature range it was fitted on."""


class CorrelationWarning(ThermocalWarning):
    """A validation test is not weakly correlated with the modelling test."""


class ConditioningWarning(ThermocalWarning):
    """A least-squares design is badly conditioned."""


class PlausibilityWarning(ThermocalWarning):
    """A value no sensor or chamber produces: a wrong unit or conversion is likely."""


class UnitWarning(ThermocalWarning):
    """A unit was not stated and a default was taken, or an option contradicts the file."""


class TextLayoutWarning(ThermocalWarning):
    """A text log's banner lines or mangled lines were skipped (they are named)."""


class TextEncodingWarning(ThermocalWarning):
    """A text file is not UTF-8 and was read in another encoding."""
