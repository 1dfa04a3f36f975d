"""Chapter 4, force and angle limits (paper Sec. 5, Fig. 4; the limits have no equation number).

* :mod:`.runs`: the switched closed loop run many times at once by the compiled
  event-located integrator, read as tracking errors;
* :mod:`.sections`: one run at a time on the adaptive reference integrator: the
  stroboscopic section, ``section_sweep``, ``sweep_angle_limit``;
* :mod:`.verdicts`: ``limit_verdicts``, the regime under an angle limit and a force cap
  decided by :mod:`lib.dynamics.verdicts`; ``extend_undecided``, ``regime_edges``;
* :mod:`.confirm`: ``confirm_limit_verdicts`` (and ``confirmed_limit_verdicts``, both steps), every verdict that claims an attractor
  decided again from starts moved by 1e-12, ``transient`` where the attractors differ;
* :mod:`.attractors`: the closed loop's mirror symmetry on the eight, the attractors the
  starts reach, the Lyapunov exponent over horizons;
* :mod:`.torus`: where the quasi-periodic regime is born, a Neimark-Sacker bifurcation of the
  period-1 orbit along the cap (``torus_birth``), and the invariant circle's rotation number.

``lib.limits`` is a public face: it re-exports the names readers use.
"""

from .runs import error_state, SwitchedRuns, switched_runs, STEPS_PER_PERIOD
from .sections import stroboscopic_section, Regime, classify, section_sweep, sweep_angle_limit
from .verdicts import limit_verdicts, extend_undecided, UNDECIDED_FACTOR, regime_edges, LIMIT_DEFAULTS
from .confirm import confirm_limit_verdicts, confirmed_limit_verdicts
from ..integrators.switched import SwitchedLoop, Segments
from ..dynamics.lyapunov import largest_lyapunov, LyapunovEstimate
from ..dynamics.sections import distinct_points, section_period, section_margin
from ..angles import state_difference

__all__ = ["error_state", "stroboscopic_section", "Regime", "classify", "section_sweep", "sweep_angle_limit",
           "SwitchedRuns", "switched_runs", "limit_verdicts", "extend_undecided", "UNDECIDED_FACTOR",
           "regime_edges", "LIMIT_DEFAULTS", "confirm_limit_verdicts", "confirmed_limit_verdicts", "STEPS_PER_PERIOD", "SwitchedLoop", "Segments",
           "largest_lyapunov", "LyapunovEstimate", "distinct_points", "section_period",
           "section_margin", "state_difference"]
