"""The study: scenes with known answers, accuracy measures, convergence rates, the claims ledger,
stability verdicts.

``scenes`` (manufactured and membranes loads), ``accuracy`` and ``contact_rows`` (one solve →
one tidy row), ``profiles`` (Γ profiles for figures), ``rates`` (fitted slopes), ``claims``
(the ledger's criterion and every claim), ``verdict`` (one space's stability verdict by the
ledger's criterion, ``infsup-contact verdict``), ``beta_batches`` (β_h of a batch of mesh pairs
for any model: the one path of the membranes' and the elastic β_h tables), ``batches`` (how
the workflow cuts the pairs into jobs), ``selection`` (the rows a figure shows). Imports
``solvers`` and the stages below it.
"""
