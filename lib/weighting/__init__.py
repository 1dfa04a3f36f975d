"""Chapter 6, the allocation beyond the paper (the open problem after eq. (24)).

* :mod:`.batch`: batch runs of the closed loop under any allocation, their steady metrics;
* :mod:`.verdicts`: the full closed loop as a period map, decided by
  :mod:`lib.dynamics.verdicts`: ``closed_loop_verdicts`` (w_phi = 0 is (25)-(26));
* :mod:`.rotating_frame`: the frame rotating with the circle's reference;
* :mod:`.circle`: the circle under the weighted allocation exactly: its steady motion,
  eigenvalues and the weight where it loses stability;
* :mod:`.comparison`: the weighted law against the paper's on Fig. 5's map, the trade-off
  boundary, ``held``, ``verdict_runs``.

``lib.weighting`` is a public face: it re-exports the names readers use.
"""

from .batch import BatchResult, closed_loop_batch, steady_metrics
from .verdicts import LOOP_VERDICT_DEFAULTS, closed_loop_verdicts
from .comparison import (verdict_runs, held, stability_boundary, refine_boundary, extend_undecided,
                         MapComparison, compare_on_map, limits_comparison)
from .circle import circle_steady_state, circle_weight_limit, circle_weight_sweep, circle_error_weight

__all__ = ["BatchResult", "closed_loop_batch", "steady_metrics", "LOOP_VERDICT_DEFAULTS", "closed_loop_verdicts",
           "verdict_runs", "held", "stability_boundary", "refine_boundary", "extend_undecided",
           "MapComparison", "compare_on_map", "limits_comparison", "circle_steady_state",
           "circle_weight_limit", "circle_weight_sweep", "circle_error_weight"]
