"""Reference implementation of Korczak (2014), *Tracking control of an underactuated rigid
body with a coupling input force*. Each equation of the paper is defined once; data
flows one way, from the model core through the integrators to the analyses, the
figures and, on top, the book's verdicts on the paper (``lib.paper``). The map of
modules is ``lib/README.md``; ``tests/test_layout.py`` checks that the import graph
is acyclic and flows this way.
"""
