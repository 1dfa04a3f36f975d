"""Stability of the uncontrolled rotation (paper Sec. 6, eqs. (32)-(37), Fig. 5): the
names Chapter 5 and other code use, gathered from where each is defined.

* :mod:`lib.rotation.equations`: (32), (33), (37) and p0^(k) derived with sympy, and as printed;
* :mod:`lib.rotation.circle_global`: the circle in closed form, (33)-(36), and its global behaviour;
* :mod:`lib.rotation.field`: (32) in the phase s = Theta t, the field the integrators run;
* :mod:`lib.rotation`: the reduced rotation for many (R, Theta) at once, the Fig. 5 sweep,
  periodic orbits and Lyapunov exponents;
* :mod:`lib.rotation.verdicts`: the decisive verdicts of Fig. 5 (orbits, Floquet multipliers,
  Lyapunov exponents, drift), by the one decision procedure of :mod:`lib.dynamics.verdicts`;
* :mod:`lib.rotation.attractor`: the attracting orbits of one point, and a map's summary;
* :mod:`lib.trajectories`: the Fourier series of the eight's tangent angle.
"""

from .rotation.circle import (circle_critical_radius, circle_eigenvalues, circle_equilibria, circle_jacobian,
                              circle_rotation_rhs)
from .rotation.circle_global import circle_final_state, circle_slipping_coexists
from .rotation.reduced import ENGINES, reduced_rotation, rotation_sweep, steps_per_period
from .dynamics.sampled import classify_samples, sampled_range
from .rotation.attractor import MapSummary, RotationAttractor, map_summary, rotation_attractor
from .rotation.verdicts import FIG5_GRID, REGIMES, eight_rotation_sweep, rotation_verdicts
from .rotation.fig5 import fig5_map
from .rotation.equations import (RotationEquation, corrected_p0, derive_eight_equation,
                                 derive_rotation_equation, printed_eq33, printed_eq37, printed_p0)
from .trajectories import PAPER_HEADING_SERIES, eight_heading_fourier, heading_series

__all__ = [
    "RotationEquation", "derive_rotation_equation", "printed_eq33", "derive_eight_equation", "printed_eq37",
    "corrected_p0", "printed_p0", "circle_equilibria", "circle_critical_radius", "circle_eigenvalues",
    "circle_jacobian", "circle_rotation_rhs", "circle_final_state", "circle_slipping_coexists",
    "steps_per_period", "reduced_rotation", "classify_samples", "sampled_range", "rotation_sweep",
    "eight_rotation_sweep", "fig5_map", "FIG5_GRID", "REGIMES", "rotation_verdicts", "rotation_attractor", "RotationAttractor",
    "map_summary", "MapSummary", "ENGINES", "eight_heading_fourier", "heading_series", "PAPER_HEADING_SERIES",
]
