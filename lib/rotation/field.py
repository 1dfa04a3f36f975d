"""The reduced rotation equation (32) as a vector field in the phase s = Theta t: the one
definition that the batch integrator (numpy) and its compiled engine (numba) both run.

With x_d = R X(s), y_d = R Y(s) on the reference and w = d phi / ds, (32) divided by
I_C Theta^2 reads

    phi' = w,
    w'   = -A w + B (Y' cos phi - X' sin phi) + C (Y'' cos phi - X'' sin phi),

with A = c_phi / (I_C Theta), B = a R c / (I_C Theta), C = a R m / I_C. On the eight
(28) this is (37) (corrected), on the circle (27) it is (33) in phi.
"""

from __future__ import annotations

import numpy as np

from ..params import Body

__all__ = ["coefficients", "rotation_rates", "rotation_rates_dphi", "rotation_rates_cs"]


def coefficients(body: Body, R, Theta):
    """(A, B, C) of the phase form of (32) for arrays R (m), Theta (rad/s).

    Parameters
    ----------
    body : Body
        The body.
    R, Theta : array_like
        Radii (m) and rates (rad/s).

    Returns
    -------
    A, B, C : numpy.ndarray
        The coefficients of the phase form (dimensionless), broadcast.
    """
    A = body.c_phi / (body.I * Theta)
    B = body.a * R * body.c / (body.I * Theta)
    C = body.a * R * body.m / body.I
    return A, B, C


def rotation_rates(phi, w, A, B, C, X1, Y1, X2, Y2):
    """(phi', w') of the phase form of (32), with X1 = X', Y1 = Y', X2 = X'', Y2 = Y''
    the unit reference's derivatives at the phase. Pure arithmetic and cos/sin, so
    numba compiles the same function for the compiled engine.

    Parameters
    ----------
    phi, w : array_like
        Heading (rad) and w = d phi / ds.
    A, B, C : array_like
        :func:`coefficients`.
    X1, Y1, X2, Y2 : array_like
        The unit reference's first and second derivatives at the phase.

    Returns
    -------
    tuple of numpy.ndarray
        (d phi / ds, d w / ds).
    """
    return w, (B * Y1 + C * Y2) * np.cos(phi) - (B * X1 + C * X2) * np.sin(phi) - A * w


def rotation_rates_dphi(phi, B, C, X1, Y1, X2, Y2):
    """d w' / d phi of :func:`rotation_rates` (d w' / d w = -A), for the variational equation.

    Parameters
    ----------
    phi : array_like
        Heading (rad).
    B, C : array_like
        :func:`coefficients`.
    X1, Y1, X2, Y2 : array_like
        The unit reference's derivatives at the phase.

    Returns
    -------
    numpy.ndarray
        d w' / d phi.
    """
    return -(B * Y1 + C * Y2) * np.sin(phi) - (B * X1 + C * X2) * np.cos(phi)


def rotation_rates_cs(cp, sp, w, A, B, C, X1, Y1, X2, Y2):
    """(phi', w', d w'/d phi): :func:`rotation_rates` and :func:`rotation_rates_dphi` at
    once, given cp = cos phi and sp = sin phi instead of phi, for the compiled engine, which
    takes a stage's pair from its step's (:func:`lib.integrators.trig.cos_sin_near`). The same
    operations in the same order as the two definitions, so at cp = cos phi, sp = sin phi the
    values are theirs bit for bit (``tests/test_rotation_verdicts.py`` checks it at random states).

    Parameters
    ----------
    cp, sp : array_like
        cos phi and sin phi.
    w, A, B, C, X1, Y1, X2, Y2 : array_like
        As in :func:`rotation_rates`.

    Returns
    -------
    tuple of numpy.ndarray
        (d phi / ds, d w / ds, d w' / d phi).
    """
    P = B * Y1 + C * Y2
    Q = B * X1 + C * X2
    return w, P * cp - Q * sp - A * w, -P * sp - Q * cp
