"""Chapter 8: what the paper's limits allow, whatever the controller.

* :mod:`.bound`: under a force cap alone the periodic motions of C form a convex set; the least
  largest and RMS distance from the path, certified by a relaxation and its duality gap, beside
  a motion that reaches it (:func:`cap_bound`; cvxpy with Clarabel); the force that exact
  tracking of C needs (:func:`exact_peak_force`);
* :mod:`.motion` (with :mod:`.collocation`): the best periodic motion found under an angle limit,
  with or without the cap, by direct collocation of the full model (2)-(4) (CasADi and IPOPT),
  verified by integrating its inputs (:func:`periodic_motion`, :func:`verify_motion`), refined
  through the meshes and extrapolated in :mod:`.study` (``mesh_study``, ``richardson``);
* :mod:`.tracker`: a controller that reaches such a motion, the periodic LQR of its
  linearisation with the limits enforced in the loop (:func:`track_motion`), decided by the
  book's procedure in :mod:`.verdict` (:func:`motion_verdict`, its basin, and the verdict of
  the loop under a push);
* :mod:`.demand`: the force that exact tracking of C and of P needs over Fig. 5's grid;
* :mod:`.loop`: any of the book's closed loops decided by the book's orbit procedure and measured;
* :mod:`.study` and :mod:`.compare`: the chapter's computations, each one call shared with the
  report, and every law of the book under each limit setting beside the best motion and the bound;
* :mod:`.margins`: the tracker planned with a margin under the limits, run on a wrong plant and
  under a push, the entry run open loop there and from disturbed starts (its measured margin),
  and the headline comparison on a second eight.
"""

from .bound import CapBound, cap_bound, exact_peak_force
from .motion import PeriodicMotion, periodic_motion, verify_motion
from .tracker import PeriodicLQR, periodic_lqr, track_motion
from .verdict import MotionVerdict, motion_verdict

__all__ = ["CapBound", "cap_bound", "exact_peak_force", "PeriodicMotion", "periodic_motion", "verify_motion",
           "PeriodicLQR", "periodic_lqr", "track_motion", "MotionVerdict", "motion_verdict"]
