"""A result's repr is one line that says what it holds (issue 59: print(cap_bound(...)) wrote about
1,580 lines, PeriodicMotion and Entry as many)."""

from dataclasses import dataclass

import numpy as np
import pytest

from lib.machinery.summary import Summarised, summary
from lib.optimal.bound import cap_bound
from lib.params import Body


@dataclass(frozen=True, repr=False)
class _Result(Summarised):
    value: float
    n: int
    kind: str
    states: np.ndarray
    law: object


def test_a_summary_writes_scalars_by_value_and_arrays_by_shape_on_one_line():
    r = _Result(0.1076931234, 3, "eight", np.zeros((64, 6)), np.sin)
    assert repr(r) == "_Result(value=0.107693, n=3, kind='eight', states=array(64, 6), law=<sin>)"
    with pytest.raises(TypeError, match="dataclass"):
        summary(3.0)


def test_the_bound_prints_as_one_short_line():
    b = cap_bound(Body(), 2.0, np.pi / 4, 4.0, nodes=16)
    text = repr(b)
    assert "\n" not in text and len(text) < 600, text
    assert text.startswith("CapBound(") and f"max_error={b.max_error:.6g}" in text
