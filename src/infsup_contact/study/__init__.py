"""The study: scenes with known answers, accuracy measures, convergence rates, the claims ledger,
stability verdicts.

``contact/`` (the scenes and their registry, one solve → one tidy row, accuracy, Γ profiles,
fitted rates), ``beta/`` (how the workflow cuts mesh pairs into jobs, β_h of a batch for any
model, the elastic pair, the rows a figure shows), ``face/`` (the face studies of the 3D models
and their tables), ``machines/`` (the checks under every BLAS code path and their ledgers),
``claims/`` (the ledger's criterion and every claim), ``patch/`` (the patch tests), ``verdict``
(one space's stability verdict by the ledger's criterion, ``infsup-contact verdict``) and
``producers`` (other codes' systems certified). Imports ``solvers``, ``contact`` and the stages below them.
"""
