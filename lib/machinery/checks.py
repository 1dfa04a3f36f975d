"""The one set of argument validators of the public API.

Every public entry point of ``lib`` checks its arguments with these few
functions, so a wrong argument fails the same way everywhere:

* a wrong *type* (a str, a bool, None, a list where a number belongs) raises
  :class:`TypeError`;
* a wrong *value* (NaN, inf, a negative radius, a NaN inside an array) raises
  :class:`ValueError`;

and both messages start with the argument's name (and, for arrays, name the
first bad index), e.g. ``"R must be a finite number, got nan"`` or
``"Theta[3] must be finite, got nan"``.

They are for the public edge (constructors, sweeps, ``simulate``); inner loops
call unvalidated kernels. The methods' budget (:mod:`lib.machinery.domain`: a run refused
before it starts when its steps or stiffness would exceed a stated budget) is re-exported
here, so that every entry checks through this one module.
"""

from __future__ import annotations

import numbers
from typing import Any, Iterable, Mapping

import numpy as np

from .domain import (H_DAMP, MAX_DAMPING_PERIODS, MAX_GRID_POINTS, MAX_ODE_STEPS, MAX_RUN_STEPS,  # re-exported
                     MAX_SAMPLES, MAX_STEPS, RK4_REACH, STEPS_PER_RADIAN, by_scale, grid_budget, heading_damping,
                     loop_domain, loop_modes, path_budget, path_extremes, rate_culprit, run_steps, scale_culprit,
                     slow_rate, steps_domain, within_budget)

__all__ = ["number", "integer", "array", "one_of", "flag", "instance", "options"]


def _is_real(value: Any) -> bool:
    return (isinstance(value, (numbers.Real, np.floating, np.integer))
            and not isinstance(value, (bool, np.bool_)))


def number(name: str, value: Any, *, positive: bool = False, nonnegative: bool = False,
           nonzero: bool = False, finite: bool = True, maximum: float | None = None,
           unit: str = "") -> float:
    """A real scalar, checked and returned as a float.

    Parameters
    ----------
    name : str
        The argument's name, as the caller's signature spells it (starts the message).
    value : Any
        The value passed; ints, floats and numpy scalars (and 0-d arrays) are numbers;
        bools, strings, None and sequences are not.
    positive, nonnegative, nonzero : bool
        Require value > 0, value >= 0 or value != 0.
    finite : bool
        Reject NaN and +-inf (default). With ``finite=False`` inf passes but NaN never does.
    maximum : float, optional
        Require value <= maximum.
    unit : str
        Appended to the value in messages (e.g. ``"m"``).

    Returns
    -------
    float
        ``value`` as a Python float.

    Raises
    ------
    TypeError
        If ``value`` is not a real number (a bool counts as not a number).
    ValueError
        If it is NaN, infinite (when ``finite``) or outside the required range.
    """
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    if not _is_real(value):
        raise TypeError(f"{name} must be a real number, got {type(value).__name__} {value!r}")
    v = float(value)
    got = f"got {value!r}" + (f" {unit}" if unit else "")
    if np.isnan(v) or (finite and not np.isfinite(v)):
        raise ValueError(f"{name} must be a finite number, {got}")
    if positive and not v > 0:
        raise ValueError(f"{name} must be positive, {got}")
    if nonnegative and not v >= 0:
        raise ValueError(f"{name} must be non-negative, {got}")
    if nonzero and v == 0:
        raise ValueError(f"{name} must be non-zero, {got}")
    if maximum is not None and not v <= maximum:
        raise ValueError(f"{name} must be at most {maximum}, {got}")
    return v


def integer(name: str, value: Any, *, minimum: int | None = None) -> int:
    """An integer, checked and returned as an int.

    Parameters
    ----------
    name : str
        The argument's name.
    value : Any
        An int or numpy integer (a bool, or a float such as 3.0, is rejected).
    minimum : int, optional
        Require value >= minimum.

    Returns
    -------
    int
        ``value`` as a Python int.

    Raises
    ------
    TypeError
        If ``value`` is not an integer.
    ValueError
        If it is below ``minimum``.
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Integral, np.integer)):
        raise TypeError(f"{name} must be an integer, got {type(value).__name__} {value!r}")
    v = int(value)
    if minimum is not None and v < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}, got {v}")
    return v


def options(given: Mapping[str, Any], defaults: Mapping[str, Any], minima: Mapping[str, int],
            extra: Iterable[str] = ()) -> dict:
    """A procedure's keyword options merged over its defaults and checked: the names in
    ``minima`` are integers at least that, every other default a positive number. The sweeps'
    ``**options`` (Chapters 4 to 7) are checked by it.

    Parameters
    ----------
    given : Mapping
        The options passed (``**options``).
    defaults : Mapping
        Every option's default.
    minima : Mapping
        The integer options and their least values.
    extra : Iterable of str
        Names accepted besides the defaults, left out of the result (the caller reads them
        from ``given``).

    Returns
    -------
    dict
        The defaults updated with ``given``, each value checked.

    Raises
    ------
    TypeError
        Naming the unknown options and the known ones, or an option of the wrong type.
    ValueError
        Naming an option out of its range.
    """
    known = set(defaults) | set(extra)
    unknown = set(given) - known
    if unknown:
        raise TypeError(f"unknown option(s) {sorted(unknown)}; known: {sorted(known)}")
    o = dict(defaults, **{k: v for k, v in given.items() if k in defaults})
    return {name: integer(name, v, minimum=minima[name]) if name in minima else number(name, v, positive=True)
            for name, v in o.items()}


def _first_bad(mask: np.ndarray) -> str:
    """The index of the first True entry, ``"[2, 1]"``; empty for a scalar (no ``"[]"``)."""
    idx = np.argwhere(mask)[0]
    return "[" + ", ".join(str(int(i)) for i in idx) + "]" if idx.size else ""


def array(name: str, value: Any, *, shape: tuple | None = None, finite: bool = True,
          positive: bool = False, nonnegative: bool = False, ndim: int | None = None,
          nonempty: bool = False) -> np.ndarray:
    """A real array (float64), checked element by element.

    Parameters
    ----------
    name : str
        The argument's name.
    value : Any
        A number, sequence or array of real numbers; strings, bools and objects are rejected.
    shape : tuple, optional
        Required shape; ``None`` in an entry matches any length on that axis, and
        a trailing ``...`` (Ellipsis) as the first entry allows any leading axes,
        e.g. ``(..., 3)``.
    finite : bool
        Reject NaN and +-inf entries (default); NaN is rejected in any case.
    positive, nonnegative : bool
        Require every entry > 0 or >= 0.
    ndim : int, optional
        Required number of axes.
    nonempty : bool
        Reject an array with no entries.

    Returns
    -------
    numpy.ndarray
        ``value`` as a float64 array (a new array when a conversion was needed).

    Raises
    ------
    TypeError
        If ``value`` holds something other than real numbers (str, bool, object).
    ValueError
        If the shape is wrong, or an entry is NaN, infinite or out of range; the
        message names the first bad index, e.g. ``"R[3] must be finite, got nan"``.
    """
    if isinstance(value, (str, bytes)) or value is None:
        raise TypeError(f"{name} must be an array of real numbers, got {type(value).__name__} {value!r}")
    raw = np.asarray(value)
    if raw.dtype.kind not in "iuf":
        raise TypeError(f"{name} must be an array of real numbers, got dtype {raw.dtype} ({value!r:.80})")
    arr = raw.astype(float, copy=False)
    if ndim is not None and arr.ndim != ndim:
        raise ValueError(f"{name} must have {ndim} axis(es), got shape {arr.shape}")
    if shape is not None:
        want = tuple(shape)
        lead = bool(want) and want[0] is Ellipsis
        tail = want[1:] if lead else want
        ok = (arr.ndim >= len(tail)) if lead else (arr.ndim == len(tail))
        if ok:
            got_tail = arr.shape[arr.ndim - len(tail):] if tail else ()
            ok = all(w is None or w == g for w, g in zip(tail, got_tail))
        if not ok:
            txt = ", ".join("..." if w is Ellipsis else ("n" if w is None else str(w)) for w in want)
            txt += "," if len(want) == 1 else ""
            raise ValueError(f"{name} must have shape ({txt}), got shape {arr.shape}")
    if nonempty and arr.size == 0:
        raise ValueError(f"{name} must not be empty")
    bad = np.isnan(arr) | (~np.isfinite(arr) if finite else False)
    if np.any(bad):
        i = _first_bad(bad)
        raise ValueError(f"{name}{i} must be finite, got {float(arr[tuple(np.argwhere(bad)[0])])!r}")
    for flag_, cond, word in ((positive, arr > 0, "positive"), (nonnegative, arr >= 0, "non-negative")):
        if flag_ and not np.all(cond):
            j = np.argwhere(~cond)[0]
            raise ValueError(f"{name}{_first_bad(~cond)} must be {word}, got {float(arr[tuple(j)])!r}")
    return arr


def one_of(name: str, value: Any, options: Iterable) -> Any:
    """One of a fixed set of options (e.g. ``kind`` in ``("eight", "circle")``).

    Parameters
    ----------
    name : str
        The argument's name.
    value : Any
        The value passed.
    options : iterable
        The admissible values.

    Returns
    -------
    Any
        ``value`` unchanged.

    Raises
    ------
    ValueError
        If ``value`` is not among ``options`` (the message lists them).
    """
    opts = tuple(options)
    try:
        ok = value in opts
    except TypeError:            # an unhashable value against a dict or set
        ok = False
    if not ok:
        raise ValueError(f"{name} must be one of {list(opts)}, got {value!r}")
    return value


def flag(name: str, value: Any) -> bool:
    """A boolean switch: True or False (Python or numpy bool), nothing else.

    Parameters
    ----------
    name : str
        The argument's name.
    value : Any
        The value passed.

    Returns
    -------
    bool
        ``value`` as a Python bool.

    Raises
    ------
    TypeError
        If ``value`` is not a bool (1, "yes" and None are rejected).
    """
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name} must be True or False, got {type(value).__name__} {value!r}")
    return bool(value)


def instance(name: str, value: Any, cls: type, what: str | None = None) -> Any:
    """An object of a given class (a ``Body``, a ``Limits``, ...).

    Parameters
    ----------
    name : str
        The argument's name.
    value : Any
        The value passed.
    cls : type
        The required class.
    what : str, optional
        How the message names the class (default ``lib.<module>.<Class>``).

    Returns
    -------
    Any
        ``value`` unchanged.

    Raises
    ------
    TypeError
        If ``value`` is not an instance of ``cls``.
    """
    if not isinstance(value, cls):
        what = what or f"{cls.__module__}.{cls.__qualname__}"
        raise TypeError(f"{name} must be a {what}, got {type(value).__name__}")
    return value
