"""Chapter 7: tracking the centre of percussion P instead of the centre of mass C.

P = C + s_P e1, s_P = -I_C / (m a), is the point of the body axis whose acceleration the
lateral force does not enter (:mod:`.derivation`, sympy; :mod:`.point`, numbers). Its
zero dynamics (P exactly on a path) are one first-order equation for the heading, solved in
closed form on the circle (:mod:`.zero_dynamics`); a law with an integrator on the thrust
makes P's error obey a chosen linear equation (:mod:`.law`, :mod:`.run`); the Fig. 5 map
under the new law is decided by :mod:`lib.dynamics.verdicts` (:mod:`.sweep`, on the
heading's exact period map, :mod:`.engine`); the side-by-side comparison with the paper's
law is in :mod:`.compare`, its figures in :mod:`.figures`.
"""

from .derivation import PointDerivation, derive_point
from .law import DEFAULT_POLE, applied_force, error_polynomial, law_inputs
from .point import (body_state_from_point, centre_of_percussion, drag_mismatch, lateral_drag_speed,
                    point_accel, point_state)
from .run import PercussionResult, designed_error_deviation, point_error, simulate
from .compare import SteadyMotion, paper_steady, path_distance, percussion_steady, steady_table
from .sweep import SWEEP_DEFAULTS, heading_sweep, percussion_fig5_map, rotation_sweep  # rotation_sweep: the former name
from .zero_dynamics import (CircleSteadyMotion, circle_lock_radius, circle_slip, circle_steady_motion,
                            frozen_lock, heading_rate, path_drive, zero_dynamics_run)

__all__ = ["PointDerivation", "derive_point", "DEFAULT_POLE", "applied_force", "error_polynomial", "law_inputs",
           "body_state_from_point", "centre_of_percussion", "drag_mismatch", "lateral_drag_speed", "point_accel",
           "point_state", "PercussionResult", "point_error", "simulate", "designed_error_deviation",
           "CircleSteadyMotion", "circle_lock_radius",
           "circle_steady_motion", "circle_slip", "frozen_lock", "heading_rate", "path_drive", "zero_dynamics_run",
           "SteadyMotion", "paper_steady", "path_distance", "percussion_steady", "steady_table", "SWEEP_DEFAULTS",
           "percussion_fig5_map", "heading_sweep"]
