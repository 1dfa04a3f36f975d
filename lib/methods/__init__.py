"""The Methods page's studies of the book's own estimators: whether a verdict's error bar is
honest, measured against the spread of the same estimate over independent starts
(:mod:`.calibration`: Fig. 5's points, Chapter 4's angle limits, the heading's variogram, Fig. 5's
exponents decided again on a finer map), and the same at the points whose lost or chaotic verdict
lies nearest its line (:mod:`.borderline`: the sign test of the ratios' lean, the t law of an
error read from few batches). They run the flows of :mod:`lib.rotation` and :mod:`lib.limits`
and the procedure of :mod:`lib.dynamics`, which import nothing from here.
"""

__all__ = ["calibration", "borderline"]
