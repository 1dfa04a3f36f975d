"""What a number on the page is, and how its kind is written.

A number the book prints is one of a few kinds (``Methods``, "A number and its kind"):

- **exact**: a closed form, a symbolic or a converged computation: rounded to nearest;
- **certified lower bound**: no motion or controller does better: rounded **down**, so that the
  printed value is still a bound;
- **certified upper bound**: rounded **up**, for the same reason;
- **at most** / **at least**: a bound that holds to the accuracy of the computation that gave it
  (an integration's tolerance, the largest value over a run, a tolerance the book sets), not
  certified: rounded up / down. A value at round-off scale is printed as such a bound, the one its
  method guarantees, never as the last bits one machine produced;
- **best found**: the value of a motion a local optimiser found: an upper bound on the least
  possible (rounded up), never called "the best";
- **estimate**: a statistic of a run, written with its standard error (``0.30 ± 0.02``), the
  error rounded up;
- **numerical estimate**: a deterministic computation that no method certifies (a Floquet
  multiplier from finite differences), written with its stated error (``0.030 ± 0.021``): the
  spread over the method's own choices (differencing steps, h and h / 2), the error rounded up;
- **count**: an integer, of a stated total;
- **setting**: a value the book chooses (a tolerance, a horizon, a step), written exactly as the code
  uses it: after "within" it states the book's own criterion, true by construction.

The code that computes a number says its kind by wrapping it (:func:`lower_bound`,
:func:`best_found`, ...); :func:`lib.machinery.glue.glue` then glues the text this module renders,
with the unrounded value and the kind beside it, so that a test of the built book can check every
glued bound's rounding against its value, and the words around it against its kind
(``tests/test_number_kinds.py``). Rounding toward safety is done in decimal arithmetic
(``decimal``), not by nudging a float.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from decimal import ROUND_CEILING, ROUND_FLOOR, ROUND_HALF_EVEN, Decimal
from enum import Enum

from . import checks

__all__ = ["Kind", "Number", "exact", "lower_bound", "upper_bound", "at_most", "at_least", "best_found",
           "estimate", "numerical", "count", "setting", "within_accuracy", "round_directed", "MIME", "BOUNDS",
           "ROUNDOFF"]

#: the MIME type under which a glued number carries its value and kind beside its text
MIME = "application/vnd.korczak.number+json"


class Kind(str, Enum):
    """The kind of a printed number."""

    EXACT = "exact"
    LOWER = "certified lower bound"
    UPPER = "certified upper bound"
    FOUND = "best found"
    CEILING = "at most"
    FLOOR = "at least"
    ESTIMATE = "estimate"
    NUMERICAL = "numerical estimate"
    COUNT = "count"
    SETTING = "setting"

    @property
    def rounding(self) -> str:
        """The kind's rounding, "down", "up" or "nearest"."""
        return {Kind.LOWER: "down", Kind.UPPER: "up", Kind.FOUND: "up", Kind.CEILING: "up",
                Kind.FLOOR: "down"}.get(self, "nearest")


#: the kinds that bound a quantity from one side. A number after "within", "at most", "at least",
#: "below", "above" or "up to" is one of these (or a count or a setting), so that the sentence
#: holds on any CPU
BOUNDS = (Kind.LOWER, Kind.UPPER, Kind.FOUND, Kind.CEILING, Kind.FLOOR)
#: below this magnitude a computed value of the book's quantities (of order 1 in SI units) is at
#: round-off scale. Its digits are one machine's last bits, so it is never printed as measured
#: (:func:`within_accuracy` prints the bound its method guarantees instead)
ROUNDOFF = 1e-9


#: the kinds written with an error beside them
_WITH_ERROR = (Kind.ESTIMATE, Kind.NUMERICAL)

_MODES = {"down": ROUND_FLOOR, "up": ROUND_CEILING, "nearest": ROUND_HALF_EVEN}


def _check_fmt(fmt: str) -> tuple[int, str]:
    if not isinstance(fmt, str) or len(fmt) < 3 or fmt[0] != "." or fmt[-1] not in "efg" or not fmt[1:-1].isdigit():
        raise ValueError(f"fmt: a precision and a type 'e', 'f' or 'g' such as '.4f', got {fmt!r}")
    return int(fmt[1:-1]), fmt[-1]


def round_directed(value: float, fmt: str, rounding: str) -> str:
    """``value`` written with the format ``fmt`` ('.4f', '.2e', '.3g'), rounded ``rounding``
    ("down" toward minus infinity, "up" toward plus infinity, or "nearest"), in exact decimal
    arithmetic: ``round_directed(0.10769, '.3f', 'down') == '0.107'``.

    Parameters
    ----------
    value : float
        A finite number.
    fmt : str
        A format spec with a precision and the type 'e', 'f' or 'g'.
    rounding : str
        "down", "up" or "nearest".

    Returns
    -------
    str
        The text; it lies on the stated side of ``repr(value)``, the value as Python writes it
        (within half an ulp of the double: far below any bound's own accuracy).
    """
    p, kind = _check_fmt(fmt)
    if rounding not in _MODES:
        raise ValueError(f"rounding: 'down', 'up' or 'nearest', got {rounding!r}")
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueError(f"value: a finite number, got {value!r}")
    # the double as Python writes it (its shortest decimal that reads back as the same double, within
    # half an ulp of its exact value): 0.19 is rounded as 0.19, not as 0.19000000000000000222
    d = Decimal(repr(float(value)))
    if kind == "f" or d == 0:
        exponent = -p if kind == "f" else 0
    else:                                          # 'e': p digits after the first; 'g': p in all
        exponent = d.adjusted() - (p if kind == "e" else max(p, 1) - 1)
    q = d.quantize(Decimal(1).scaleb(exponent), rounding=_MODES[rounding])
    # a decimal of at most 17 significant digits is written back exactly by the float's format
    text = format(float(q), fmt)
    if rounding != "nearest":                      # a carry (9.99 -> 10.0) may add a digit: still exact
        assert (Decimal(text) <= d) if rounding == "down" else (Decimal(text) >= d), (value, fmt, text)
    return text


@dataclass(frozen=True)
class Number:
    """A number with its kind, rendered by :meth:`text`.

    Parameters
    ----------
    value : float
        The unrounded value.
    kind : Kind
        What it is.
    fmt : str
        Its format spec ('.4f', '.2e', '.3g'); a count ignores it.
    stderr : float or None
        An estimate's standard error, or a numerical estimate's stated error (same unit), required
        for those two kinds and refused otherwise.
    total : int or None
        A count's total, if it has one.
    """

    value: float
    kind: Kind
    fmt: str = ".3g"
    stderr: float | None = None
    total: int | None = None

    def __post_init__(self):
        kind = Kind(self.kind)
        object.__setattr__(self, "kind", kind)
        if kind is Kind.COUNT:
            if isinstance(self.value, bool) or int(self.value) != self.value or self.value < 0:
                raise ValueError(f"value: a count is a non-negative integer, got {self.value!r}")
            object.__setattr__(self, "value", int(self.value))
            if self.total is not None and not (int(self.total) == self.total and self.total >= self.value):
                raise ValueError(f"total: an integer at least the count {self.value}, got {self.total!r}")
        else:
            round_directed(float(self.value), self.fmt, "nearest")          # checks value and fmt
            object.__setattr__(self, "value", float(self.value))
            if self.total is not None:
                raise ValueError(f"total: only a count has a total, not a {kind.value}")
            # a setting computed as a product (0.1 * 1e-3) differs from its decimal in the last bit only
            if kind is Kind.SETTING and abs(Decimal(self.text()) - Decimal(repr(self.value))) > \
                    Decimal(1e-12) * abs(Decimal(repr(self.value))):
                raise ValueError(f"fmt: a setting is written exactly, but {self.fmt!r} writes "
                                 f"{self.value!r} as {self.text()!r}")
        if (kind in _WITH_ERROR) != (self.stderr is not None):
            raise ValueError("stderr: an estimate carries its standard error (a numerical estimate its stated "
                             "error), and only those do")
        if self.stderr is not None and not (math.isfinite(self.stderr) and self.stderr >= 0):
            raise ValueError(f"stderr: a finite non-negative number, got {self.stderr!r}")

    def __float__(self) -> float:
        return float(self.value)

    def text(self) -> str:
        """The number as the page writes it: rounded as its kind says; an estimate as
        ``value ± stderr`` (the error rounded up, the value to the error's last digit), and so is
        a numerical estimate with its stated error."""
        if self.kind is Kind.COUNT:
            return str(self.value)
        text = round_directed(self.value, self.fmt, self.kind.rounding)
        if self.kind in _WITH_ERROR:
            text += " ± " + round_directed(self.stderr, self.fmt, "up")
        return text

    def record(self) -> dict:
        """The value, kind, format and text, as the glue's JSON companion."""
        return {"value": self.value, "kind": self.kind.value, "fmt": self.fmt, "stderr": self.stderr,
                "total": self.total, "text": self.text()}

    def _repr_mimebundle_(self, include=None, exclude=None) -> dict:
        return {"text/plain": repr(self.text()), MIME: self.record()}


def exact(value: float, fmt: str = ".3g") -> Number:
    """A closed form or a converged computation, rounded to nearest.

    Parameters
    ----------
    value : float
        The unrounded value.
    fmt : str
        Its format spec ('.4f', '.2e', '.3g').

    Returns
    -------
    Number
        The number with its kind.
    """
    return Number(value, Kind.EXACT, fmt)


def lower_bound(value: float, fmt: str = ".3g") -> Number:
    """A certified lower bound, rounded down.

    Parameters
    ----------
    value : float
        The unrounded value.
    fmt : str
        Its format spec ('.4f', '.2e', '.3g').

    Returns
    -------
    Number
        The number with its kind.
    """
    return Number(value, Kind.LOWER, fmt)


def upper_bound(value: float, fmt: str = ".3g") -> Number:
    """A certified upper bound, rounded up.

    Parameters
    ----------
    value : float
        The unrounded value.
    fmt : str
        Its format spec ('.4f', '.2e', '.3g').

    Returns
    -------
    Number
        The number with its kind.
    """
    return Number(value, Kind.UPPER, fmt)


def at_most(value: float, fmt: str = ".3g") -> Number:
    """A bound from above that holds to the accuracy of the computation behind it (an
    integration's tolerance, the largest value over a run, a tolerance the book sets), not
    certified: rounded up, so that "at most", "within" or "up to" before it stays true.

    A value at round-off scale is not printed; the bound its method guarantees is, with the method
    named beside it (``at_most(rtol * scale)``, well above the round-off).

    Parameters
    ----------
    value : float
        The unrounded value.
    fmt : str
        Its format spec ('.4f', '.2e', '.3g').

    Returns
    -------
    Number
        The number with its kind.
    """
    return Number(value, Kind.CEILING, fmt)


def at_least(value: float, fmt: str = ".3g") -> Number:
    """A bound from below that holds to the accuracy of the computation behind it, not
    certified: rounded down, so that "at least" or "above" before it stays true.

    Parameters
    ----------
    value : float
        The unrounded value.
    fmt : str
        Its format spec ('.4f', '.2e', '.3g').

    Returns
    -------
    Number
        The number with its kind.
    """
    return Number(value, Kind.FLOOR, fmt)


def within_accuracy(measured: float, accuracy: float, fmt: str = ".0e") -> Number:
    """The bound ``accuracy`` that a method guarantees (an integrator's or Newton's tolerance, scaled
    as the page states), printed in place of a ``measured`` value at round-off scale: "the run ends
    within 2e-09 rad of p_s (ten times the integrator's tolerance)", never "within 5e-14", the last
    bits of one machine, which another CPU rounds the other way.

    Parameters
    ----------
    measured : float
        What the computation gave (a distance, a difference), in the unit of ``accuracy``.
    accuracy : float
        The bound the method guarantees; at least ten times ``|measured|``, so that it holds on
        another CPU, libm or BLAS with that margin.
    fmt : str
        Its format spec (default one significant digit, '.0e').

    Returns
    -------
    Number
        ``accuracy`` as an :func:`at_most` bound, rounded up.

    Raises
    ------
    ValueError
        When ``measured`` is not finite, or lies less than ten times below ``accuracy``: then the
        measurement is not round-off, and the bound does not hold with a margin.
    """
    measured = checks.number("measured", measured)
    accuracy = checks.number("accuracy", accuracy, positive=True)
    if not 10 * abs(measured) <= accuracy:
        raise ValueError(f"accuracy: {accuracy!r} is less than ten times the measured {measured!r}: "
                         "the measurement is not round-off, or the method's bound is not the one stated")
    return at_most(float(accuracy), fmt)


def setting(value: float, fmt: str = ".3g") -> Number:
    """A value the book chooses (a tolerance, a horizon), written exactly as the code uses it.

    Parameters
    ----------
    value : float
        The setting.
    fmt : str
        A format spec that writes it exactly ('.0e' for 1e-10, '.2f' for 0.05); refused otherwise.

    Returns
    -------
    Number
        The number with its kind.
    """
    return Number(value, Kind.SETTING, fmt)


def best_found(value: float, fmt: str = ".3g") -> Number:
    """The value of a motion found by a local optimiser: an upper bound on the least possible,
    rounded up.

    Parameters
    ----------
    value : float
        The unrounded value.
    fmt : str
        Its format spec ('.4f', '.2e', '.3g').

    Returns
    -------
    Number
        The number with its kind.
    """
    return Number(value, Kind.FOUND, fmt)


def estimate(value: float, stderr: float, fmt: str = ".2f") -> Number:
    """A statistic of a run with its (calibrated) standard error, written ``value ± stderr``.

    Parameters
    ----------
    value : float
        The estimate.
    stderr : float
        Its standard error (>= 0, same unit).
    fmt : str
        The format spec of both.

    Returns
    -------
    Number
        The estimate.
    """
    return Number(value, Kind.ESTIMATE, fmt, stderr=float(stderr))


def numerical(value: float, error: float, fmt: str = ".3f") -> Number:
    """A numerical estimate that no method certifies (a Floquet multiplier from finite
    differences), written ``value ± error``: ``error`` is the stated spread over the method's own
    choices (differencing steps, the integrator's step), not a standard error of a sampled
    statistic, and the value is no bound either way.

    Parameters
    ----------
    value : float
        The estimate.
    error : float
        Its stated error (>= 0, same unit).
    fmt : str
        The format spec of both.

    Returns
    -------
    Number
        The numerical estimate.
    """
    return Number(value, Kind.NUMERICAL, fmt, stderr=float(error))


def count(n: int, total: int | None = None) -> Number:
    """A count, of ``total`` if given.

    Parameters
    ----------
    n : int
        The count (>= 0).
    total : int or None
        What it counts out of.

    Returns
    -------
    Number
        The count.
    """
    return Number(n, Kind.COUNT, total=total)
