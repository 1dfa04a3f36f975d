"""Tools for deciding what a driven motion does in the long run, independent of this
body: stroboscopic sections and their periods (:mod:`.sections`), the largest
Lyapunov exponent (:mod:`.lyapunov`), periodic orbits located by Newton's method on
a period map and their Floquet multipliers (:mod:`.orbits`)."""

from .lyapunov import LyapunovEstimate, largest_lyapunov
from .orbits import Orbit, floquet_multipliers, newton_orbit
from .sections import distinct_points, section_margin, section_period

__all__ = ["LyapunovEstimate", "largest_lyapunov", "Orbit", "floquet_multipliers", "newton_orbit",
           "distinct_points", "section_margin", "section_period"]
