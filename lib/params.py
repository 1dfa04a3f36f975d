"""Physical and feedback parameters (the paper's Table 1, printed as "Table 5").

Both classes are frozen dataclasses validated on construction (by
:mod:`lib.machinery.checks`): a non-positive or non-finite value raises :class:`ValueError`
and a value that is not a real number (a str, a bool) raises :class:`TypeError`,
both naming the offending field (and the axis index for a gain).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields

import numpy as np

from .machinery import checks

__all__ = ["Body", "Gains", "PAPER_Z0", "PAPER_DZ0", "BODY_RANGE"]

#: The initial configuration of the paper's Table (x = 1 m, y = 0 m, phi = pi/2 rad).
PAPER_Z0 = (1.0, 0.0, math.pi / 2)
#: The initial velocities of the paper's Table (the body starts at rest).
PAPER_DZ0 = (0.0, 0.0, 0.0)


#: the range of each of the body's parameters (in SI units) that the book's methods serve, with
#: absolute tolerances (1e-10 and looser) on states of order one and explicit integrators whose
#: steps scale with the ratios c/m and c_phi/I_C (``simulate`` refuses a run whose step count
#: these ratios would blow up)
BODY_RANGE = (1e-6, 1e6)


@dataclass(frozen=True)
class Body:
    """The planar rigid body of eqs. (2)-(4), defaults from the paper's Table.

    Parameters
    ----------
    m : float
        Mass (kg), > 0.
    I : float
        Moment of inertia about the centre of mass C, I_C (kg m^2), > 0.
    a : float
        Distance from C to the point where the force acts (m), > 0.
    c : float
        Linear viscous drag coefficient (N s / m), > 0.
    c_phi : float
        Rotational viscous drag coefficient (N m s), > 0.

    Raises
    ------
    TypeError
        If a value is not a real number (a str, a bool).
    ValueError
        If a value is not positive and finite, or lies outside :data:`BODY_RANGE`.
    """

    m: float = 2.0
    I: float = 0.1
    a: float = 0.4
    c: float = 0.6
    c_phi: float = 0.1

    def __post_init__(self) -> None:
        for f in fields(self):
            value = checks.number(f"Body.{f.name}", getattr(self, f.name), positive=True)
            lo, hi = BODY_RANGE
            if not lo <= value <= hi:
                raise ValueError(f"Body.{f.name} must lie in [{lo:g}, {hi:g}] (SI units), the range the "
                                 f"book's integrators and tolerances are meant for; got {value!r}")
            object.__setattr__(self, f.name, value)

    @property
    def mass_matrix(self) -> np.ndarray:
        """The mass matrix M = diag(m, m, I_C) of eq. (22) (kg, kg, kg m^2)."""
        return np.diag([self.m, self.m, self.I])

    @property
    def drag(self) -> np.ndarray:
        """The drag coefficients (c, c, c_phi), so that N(dz) = drag * dz in eq. (22)."""
        return np.array([self.c, self.c, self.c_phi])


def _as_gain(owner: str, name: str, value) -> np.ndarray:
    if np.ndim(value) == 0:
        arr = np.full(3, checks.number(f"{owner}.{name}", value, positive=True))
    else:
        arr = np.array(checks.array(f"{owner}.{name}", value), dtype=float)
        if arr.shape != (3,):
            raise ValueError(f"{owner}.{name} must be a scalar or have length 3 (x, y, phi), got shape {arr.shape}")
        checks.array(f"{owner}.{name}", arr, positive=True)
    arr.setflags(write=False)
    return arr


@dataclass(frozen=True)
class Gains:
    """Diagonal PD gains of the computed-torque law, eq. (23).

    ``kp`` (N/m on x, y; N m/rad on phi) and ``kv`` (N s/m; N m s/rad) are
    each a scalar (same gain on every axis) or a length-3 sequence for the
    axes (x, y, phi). Defaults are the paper's Table: Kp = 5.2, Kv = sqrt(10.4).
    The phi entries enter tau_phi only, which the position-only allocation
    (25)-(26) ignores.

    Parameters
    ----------
    kp : float or sequence of 3 floats
        Proportional gains (N/m, N/m, N m/rad), > 0; stored as a read-only array (3,).
    kv : float or sequence of 3 floats
        Derivative gains (N s/m, N s/m, N m s/rad), > 0; stored as a read-only array (3,).

    Raises
    ------
    TypeError
        If a gain is not a real number (a str, a bool), naming it.
    ValueError
        If a gain is not positive and finite (its axis index named), or has a length
        other than 3.
    """

    kp: float | tuple = 5.2
    kv: float | tuple = field(default=math.sqrt(10.4))

    def __post_init__(self) -> None:
        object.__setattr__(self, "kp", _as_gain("Gains", "kp", self.kp))
        object.__setattr__(self, "kv", _as_gain("Gains", "kv", self.kv))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Gains):
            return NotImplemented
        return bool(np.array_equal(self.kp, other.kp) and np.array_equal(self.kv, other.kv))

    def __hash__(self) -> int:
        return hash((tuple(self.kp), tuple(self.kv)))
