"""Chapter 8's studies: the computations its page and the report quote, each one call that
:mod:`lib.optimal`'s library serves (it imports nothing from here).

* :mod:`.study`: the bound over the caps and meshes, the best motions under each limit setting
  refined through the meshes and extrapolated (``limit_motions``, ``mesh_study``, ``richardson``),
  the multi-start, the entries from the paper's start and their basin;
* :mod:`.compare`: every law of the book under each limit setting beside the best motion and the
  bound (``limits_study``), and the chapter's tables;
* :mod:`.margins`: the tracker planned with a margin, run on a wrong plant and under a push, the
  entry run open loop there and from disturbed starts (its measured margin), and the headline
  comparison on a second eight;
* :mod:`.demand`: the force that exact tracking of C and of P needs over Fig. 5's grid.
"""

from . import compare, demand, margins, study

__all__ = ["compare", "demand", "margins", "study"]
