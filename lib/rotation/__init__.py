"""Chapter 5, stability of the uncontrolled rotation (paper Sec. 6, eqs. (32)-(37), Fig. 5).

* :mod:`.equations`: (32), (33), (37) and p0 derived with sympy, and as printed;
* :mod:`.circle`: the circle's rotation (33) in closed form: equilibria, (34)-(36);
* :mod:`.circle_global`: the circle's global behaviour, the bistable window;
* :mod:`.field`: (32) in phase form, the field the integrators run;
* :mod:`.reduced`: the reduced rotation over many (R, Theta): integration, period map,
  orbits, Lyapunov exponents;
* :mod:`.engine`: the reduced rotation as a period map for the verdicts (compiled, exact Jacobian);
* :mod:`.verdicts`: the decisive Fig. 5 verdicts, ``eight_rotation_sweep``;
* :mod:`.fig5`: the book's Fig. 5 map, ``fig5_map``: verdicts that a chaotic transient may have
  decided taken again (transient chaos), lost headings tested over a longer horizon;
* :mod:`.attractor`: the attracting orbit one start reaches; a map's summary;
* :mod:`.slow_eight`: slow eights without integrating (the frozen and overdamped heading).

``lib.rotation`` is a public face: it re-exports the names of the reduced rotation
(:mod:`.reduced`) as before; :mod:`lib.stability` gathers the names Chapter 5 uses.
"""

from .reduced import (steps_per_period, reduced_rotation, rotation_sweep, ENGINES, rotation_period_map,
                      rotation_orbit, RotationLyapunov, rotation_lyapunov, WINDING)
from ..dynamics.sampled import classify_samples, sampled_range, sampled_extremes
from .slow_eight import SlowEight, slow_eight_prediction

__all__ = ["steps_per_period", "reduced_rotation", "classify_samples", "sampled_range", "sampled_extremes",
           "rotation_sweep", "ENGINES", "rotation_period_map", "rotation_orbit", "RotationLyapunov",
           "rotation_lyapunov", "WINDING", "SlowEight", "slow_eight_prediction"]
