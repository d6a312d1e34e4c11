"""The study: scenes with known answers, accuracy measures, convergence rates, the claims ledger.

``scenes`` (manufactured and membranes loads), ``accuracy`` and ``contact_rows`` (one solve →
one tidy row), ``profiles`` (Γ profiles for figures), ``rates`` (fitted slopes), ``claims``
(the ledger's criterion and every claim). Imports ``solvers`` and the stages below it.
"""
