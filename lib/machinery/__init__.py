"""The book's machinery, used by every part: the validators of the public API
(:mod:`.checks`), the scatter and gather of the sweeps over processes or a dask cluster
(:mod:`.parallel`), a result computed once per book build and shared by pages
(:mod:`.cache`), the notebooks' glue helpers (:mod:`.glue`), and the start perturbations of
the tests' robustness mode (:mod:`.robustness`). Nothing here knows the body or the paper."""

#: the modules a reader calls
__all__ = ["checks", "domain", "parallel", "cache", "glue", "kinds", "summary", "robustness"]
