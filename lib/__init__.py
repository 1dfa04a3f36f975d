"""Reference implementation of Korczak (2014), *Tracking control of an underactuated rigid
body with a coupling input force*. Each equation of the paper is defined once; data
flows one way, from the model core through the integrators to the analyses, the
figures and, on top, the book's verdicts on the paper (``lib.paper``). The map of
modules is ``lib/README.md``; ``tests/test_layout.py`` checks that the import graph
is acyclic and flows this way.

Where to start (import the modules you need; ``import lib`` itself loads nothing else):

* ``lib.params.Body``, ``lib.params.Gains``: the body and the controller gains of the
  paper's Table;
* ``lib.trajectories.circle``, ``lib.trajectories.eight``: the references (27), (28);
* ``lib.simulate.simulate``: the closed loop (2)-(4), (23), (25)-(26), with force and
  angle limits (``lib.allocation.Limits``);
* ``lib.tracking``: the runs and numbers of Figs. 2-4 (``run``, ``steady_summary``,
  ``force_cap_sweep``);
* ``lib.stability.eight_rotation_sweep``: the verdicts of Fig. 5 over (R, Theta) grids;
* ``lib.limits.verdicts.limit_verdicts``: the regime under an angle limit and a force cap;
* ``lib.weighting.verdicts.closed_loop_verdicts``: the verdicts on the full closed loop, for any
  allocation weights (Chapter 6).

Every sweep takes ``executor=`` (any ``concurrent.futures.Executor``, a dask cluster's
included; ``lib.machinery.parallel.map_chunks``) and ``progress=`` (a progress bar, shown by default
only when run interactively: ``lib.machinery.parallel.show_progress``). Every public function checks
its arguments with ``lib.machinery.checks``: a wrong type is a ``TypeError``, a wrong value a
``ValueError``, each naming the argument (and the index in an array).

README.md's "Use the library" runs a small Fig. 5 map and a capped circle;
the book's "Library reference" page (``reference.md``) is generated from the docstrings.
"""

import os as _os

#: the model core, by module: what every chapter calls (the parts of the book are its folders)
__all__ = ["params", "model", "trajectories", "allocation", "control", "closed_loop", "simulate", "angles",
           "symbolic", "controllability", "stability"]

# numba's parallel kernels run on its OpenMP threading layer, whose threads by default spin
# while they wait at the end of a parallel loop. The verdicts call the kernels thousands of
# times on a few rows each (Newton's iterations), so the spinning thread takes a core from
# whatever else runs: on the 2-core machine, beside one other busy process, Fig. 5's sweep
# took 74 s of CPU with spinning threads and 31 s with sleeping ones (the same 31 s as on
# one thread). Waiting threads sleep unless the user chose otherwise; the results do not
# depend on it (each point of a parallel loop is computed alone).
_os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
del _os

