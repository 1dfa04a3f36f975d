"""Chapter 3, tracking the circle and the eight (paper Secs. 4-5, eqs. (23)-(31), Figs. 2-4).

* :mod:`.runs`: the runs and numbers of Figs. 2-4: a run of the closed loop, its steady
  window and summary, the eight's sensitivity, the force-cap sweep;
* :mod:`.mismatch`: tracking with a wrong model: the closed loop with the controller's own
  model, the exact error equation with a mismatch (sympy), its periodic solution.

``lib.tracking`` is a public face: it re-exports the names readers use.
"""

from .runs import (run, steady_mask, restrict, rotation_error_continuous, position_deviation_from_eq24,
                   steady_summary, refined_summary, eight_sensitivity, force_cap_sweep, saturated_intervals,
                   circle_rotation_equilibrium)
from .mismatch import mismatch_sweep

__all__ = ["run", "steady_mask", "restrict", "rotation_error_continuous", "position_deviation_from_eq24",
           "steady_summary", "refined_summary", "eight_sensitivity", "force_cap_sweep",
           "saturated_intervals", "circle_rotation_equilibrium", "mismatch_sweep"]
