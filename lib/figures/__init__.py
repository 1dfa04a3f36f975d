"""The book's figures: the tracking runs and the body (:mod:`.tracking`, Chapters 1 and 3),
the maps and sweeps of Chapters 4-6 (:mod:`.maps`), Chapter 7's (:mod:`.percussion`), and the animations (:mod:`.animation`).
Each helper takes an optional ``ax`` and returns the figure. :mod:`.interactive` draws Fig. 5
and Chapter 4's angle-limit diagram again with plotly, for the HTML pages (the book's notebooks
only; plotly is in the ``book`` extra)."""

#: the modules a reader calls, one a part of the book
__all__ = ["tracking", "maps", "percussion", "optimal", "animation", "interactive"]
