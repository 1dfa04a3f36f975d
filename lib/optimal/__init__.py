"""Chapter 8: what the paper's limits allow, whatever the controller. The library, by idea; the
chapter's own studies, which call it, live apart in :mod:`lib.optimal.studies` (nothing here
imports them).

* the bound: :mod:`.bound`, under a force cap alone the least largest and RMS distance of C from
  the path, certified by a convex relaxation and its duality gap, beside a motion that reaches it
  (:func:`cap_bound`; cvxpy with Clarabel), and the force exact tracking needs
  (:func:`exact_peak_force`); :mod:`.held`, the bound's motions as motions of the full model;
* the motions: :mod:`.motion`, the best periodic motion found under an angle limit, with or
  without the cap, by direct collocation (:mod:`.collocation`, CasADi and IPOPT), verified by
  integrating its inputs (:func:`periodic_motion`, :func:`verify_motion`); :mod:`.entry`, an entry
  manoeuvre onto one (:func:`entry_motion`);
* the tracker: :mod:`.tracker`, the periodic LQR of the motion's linearisation with the limits
  enforced in the loop (:func:`track_motion`; its Riccati equation compiled in :mod:`.riccati`),
  decided by the book's procedure on two maps in :mod:`.verdict` (:func:`motion_verdict`), under a
  push in :mod:`.pushed`, its multipliers read as estimates with a stated error in :mod:`.floquet`;
* :mod:`.loop`: any of the book's closed loops decided on two maps, h and h / 2, and measured.
"""

from .bound import CapBound, cap_bound, exact_peak_force
from .entry import Entry, entry_motion
from .motion import PeriodicMotion, periodic_motion, verify_motion
from .tracker import PeriodicLQR, periodic_lqr, track_motion
from .verdict import MotionVerdict, motion_verdict

__all__ = ["CapBound", "cap_bound", "exact_peak_force", "PeriodicMotion", "periodic_motion", "verify_motion",
           "Entry", "entry_motion", "PeriodicLQR", "periodic_lqr", "track_motion", "MotionVerdict", "motion_verdict"]
