"""The book's verdicts on the paper: the errata (:mod:`.errata`, one row per error with
the computation that proves it) and the reproduction report (:mod:`.report`, one
outcome per claim). This subpackage imports the domain modules; none of them
imports it."""

#: the modules a reader calls: the errata, the report, the front page's findings
__all__ = ["errata", "report", "findings"]
