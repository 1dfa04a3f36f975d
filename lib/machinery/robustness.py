"""Start perturbations for deciding whether a verdict rides on the last bits of a trajectory.

Two machines with different CPUs or libms differ in the last bits of every
trajectory; on a chaotic or switched motion such differences grow. A verdict
worth stating must survive them: the tests rerun every verdict from a start
moved by :data:`ROBUST_REL` (the "robustness mode" of ``tests/conftest.py``),
and the chapters quote the spread of counts that such starts produce.
"""

from __future__ import annotations

import numpy as np

__all__ = ["ROBUST_REL", "perturbed"]

#: relative size of the start perturbation of the robustness mode
ROBUST_REL = 1e-12

_SIGNS = np.random.default_rng(20140307).choice([-1.0, 1.0], size=64)


def perturbed(x, rel: float = ROBUST_REL) -> np.ndarray:
    """``x`` moved by ``rel`` times max(|x_i|, 1) in each entry, with fixed pseudo-random
    signs (so an entry that is zero, such as a start at rest, moves by ``rel``).

    Parameters
    ----------
    x : array_like
        The values.
    rel : float
        Relative size.

    Returns
    -------
    numpy.ndarray
        The moved values.
    """
    x = np.asarray(x, dtype=float)
    if not np.isfinite(rel):
        raise ValueError(f"rel must be finite, got {rel!r}")
    signs = np.resize(_SIGNS, x.shape)
    return x + rel * np.maximum(np.abs(x), 1.0) * signs
