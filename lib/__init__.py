"""Reference implementation of Korczak (2014), *Tracking control of an
underactuated rigid body with a coupling input force*.

Modules follow the flow of data: :mod:`lib.params` -> :mod:`lib.model` ->
:mod:`lib.trajectories` -> :mod:`lib.control` -> :mod:`lib.simulate` ->
analyses (:mod:`lib.symbolic`, ...) -> :mod:`lib.plotting`.
"""

__all__ = ["params", "model", "trajectories", "control", "simulate", "symbolic", "plotting", "errata"]
