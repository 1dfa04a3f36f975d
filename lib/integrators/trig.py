"""cos and sin of a stage's angle from those of its step's start, for the compiled
integrators.

A Runge-Kutta step evaluates the field at angles x0 + d close to the angle x0 at the step's
start (d a few hundredths of a radian). libm's ``sincos`` was half of the compiled rotation
map's time (``perf``, Fig. 5's sweep); the addition formulas

    cos(x0 + d) = cos x0 + (cos x0 (cos d - 1) - sin x0 sin d),
    sin(x0 + d) = sin x0 + (sin x0 (cos d - 1) + cos x0 sin d),

with cos d - 1 and sin d as their Taylor polynomials, give the stage's pair from the
step's one ``sincos`` in about half the time.

Accuracy: for |d| <= :data:`NEAR` the polynomials' remainders are below 3e-18
(d^13 / 13! and d^14 / 14! at d = 1/4); the result is within two units in the last place
(of 1) of cos and sin of the exact x0 + d, given cos x0 and sin x0 to libm's ulp
(``tests/test_trig.py`` checks it against 40-digit values; measured half a unit). Beyond
:data:`NEAR` the pair is libm's cos and sin of x0 + d, rounded. The two differ from libm's
cos and sin of the rounded sum in the last bits only: chaotic runs then follow other
trajectories; a run that settles on an orbit reaches the same one, to the orbit's accuracy,
unless the last bits choose its attractor (transient chaos, coexisting attractors).
"""

from __future__ import annotations

import math

__all__ = ["NEAR", "cos_sin_near"]

#: the largest |d| (rad) taken by the polynomials; beyond it libm's cos and sin
NEAR = 0.25


def cos_sin_near(c0: float, s0: float, x0: float, d: float) -> tuple[float, float]:
    """cos and sin of x0 + d (rad) from c0 = cos x0, s0 = sin x0: the addition formulas
    with Taylor polynomials of cos d - 1 (to d^12) and sin d (to d^11) where |d| <= :data:`NEAR`,
    libm's cos and sin of x0 + d beyond. Plain Python, which the kernels compile
    (:mod:`lib.integrators.compiled`).

    Parameters
    ----------
    c0, s0 : float
        cos x0 and sin x0.
    x0, d : float
        The step's angle and the stage's offset from it (rad).

    Returns
    -------
    tuple of float
        (cos(x0 + d), sin(x0 + d)).
    """
    if abs(d) > NEAR:
        x = x0 + d
        return math.cos(x), math.sin(x)
    d2 = d * d
    sd = d + d * d2 * (-1.0 / 6 + d2 * (1.0 / 120 + d2 * (-1.0 / 5040 + d2 * (1.0 / 362880
                                                                              + d2 * (-1.0 / 39916800)))))
    cm = d2 * (-0.5 + d2 * (1.0 / 24 + d2 * (-1.0 / 720 + d2 * (1.0 / 40320 + d2 * (-1.0 / 3628800
                                                                                 + d2 * (1.0 / 479001600))))))
    return c0 + (c0 * cm - s0 * sd), s0 + (s0 * cm + c0 * sd)
