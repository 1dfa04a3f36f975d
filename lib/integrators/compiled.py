"""The compiled engine of the batch integrator for the reduced rotation equation: the
fixed-step scheme of :func:`lib.integrators.batch.steps` (8th-order Dormand-Prince)
run over one reference period, one point per parallel numba loop, on the field
:func:`lib.rotation_field.rotation_rates` compiled from its one definition. About
ten times faster than the vectorised numpy engine on the Fig. 5 grid (see
``benchmarks/bench_eight_sweep.py``); the tests check the two agree to rounding.
"""

from __future__ import annotations

import numba
import numpy as np

from ..rotation_field import rotation_rates

__all__ = ["rotation_period"]

_rates = numba.njit(rotation_rates)


@numba.njit(cache=True, parallel=True)
def _kernel(phi, w, A, B, C, X1, Y1, X2, Y2, hA, hB, out, out_w):
    n, stages = X1.shape
    for q in numba.prange(phi.size):
        kp = np.empty(stages)
        kw = np.empty(stages)
        f, v, a_, b_, c_ = phi[q], w[q], A[q], B[q], C[q]
        for j in range(n):
            for i in range(stages):
                ps, ws = f, v
                for l in range(i):
                    ps += hA[i, l] * kp[l]
                    ws += hA[i, l] * kw[l]
                kp[i], kw[i] = _rates(ps, ws, a_, b_, c_, X1[j, i], Y1[j, i], X2[j, i], Y2[j, i])
            for i in range(stages):
                f += hB[i] * kp[i]
                v += hB[i] * kw[i]
            out[j, q] = f
            out_w[j, q] = v
        phi[q], w[q] = f, v


def rotation_period(phi, w, A, B, C, h, X1, Y1, X2, Y2, hA, hB):
    """One period of n fixed steps for N points: the unit reference's derivatives
    X1.. are tabulated at the stage phases, shape (n, stages). Returns ((phi, w) at
    every step end, each (n, N)), final phi, final w)."""
    phi, w = np.array(phi, dtype=float), np.array(w, dtype=float)
    out = np.empty((X1.shape[0], phi.size))
    out_w = np.empty_like(out)
    _kernel(phi, w, np.ascontiguousarray(A, float), np.ascontiguousarray(B, float),
            np.ascontiguousarray(C, float), X1, Y1, X2, Y2, hA, hB, out, out_w)
    return (out, out_w), phi, w
