"""A result's repr as one line that says what it holds, as numpy's and pandas' reprs do.

The book's results are frozen dataclasses that carry arrays of a period's nodes, samples and
matrices: the dataclass's own repr writes every element (``print(cap_bound(...))`` ran to about
1,580 lines). :class:`Summarised` gives such a class a one-line repr instead: its scalars by
value, its arrays by shape, its callables by name, a nested result by its class.
"""

from __future__ import annotations

import dataclasses
import numbers

import numpy as np

__all__ = ["Summarised", "summary"]


def _part(value) -> str:
    if value is None or isinstance(value, (bool, str)):
        return repr(value)
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if isinstance(value, numbers.Real):
        return f"{float(value):.6g}"
    if isinstance(value, numbers.Complex):
        return f"{complex(value):.6g}"
    if isinstance(value, np.ndarray):
        return f"array{value.shape}"
    if isinstance(value, (list, tuple, dict)):
        return f"{type(value).__name__}[{len(value)}]"
    if callable(value):
        return f"<{getattr(value, '__name__', type(value).__name__)}>"
    return f"{type(value).__name__}(...)"


def summary(obj) -> str:
    """One line naming ``obj``'s class and each of its dataclass fields: a scalar by its value
    (6 significant digits), an array by its shape, a sequence by its length, a callable by its
    name, anything else by its class.

    Parameters
    ----------
    obj : dataclass instance
        The result.

    Returns
    -------
    str
        ``"CapBound(max_error=0.107693, ..., C=array(64, 2), ...)"``.
    """
    if not dataclasses.is_dataclass(obj) or isinstance(obj, type):
        raise TypeError(f"obj must be a dataclass instance, got {type(obj).__name__}")
    parts = (f"{f.name}={_part(getattr(obj, f.name))}" for f in dataclasses.fields(obj) if f.repr)
    return f"{type(obj).__name__}({', '.join(parts)})"


class Summarised:
    """Mixin for a dataclass declared with ``repr=False``: its repr is :func:`summary`'s line."""

    __slots__ = ()

    def __repr__(self) -> str:
        return summary(self)
