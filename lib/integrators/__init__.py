"""The integrators: smooth (:mod:`.smooth`, adaptive ``solve_ivp`` with blow-up
detection), switched (:mod:`.switched`, event-located Filippov integration of the
loop with an angle limit) and batch (:mod:`.batch`, fixed-step Runge-Kutta over many
parameter points at once)."""

#: the modules a reader calls (the others are their compiled kernels and event machinery)
__all__ = ["smooth", "switched", "batch"]
