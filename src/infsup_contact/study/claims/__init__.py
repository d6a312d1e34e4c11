"""The claims engine: one set of criteria (:mod:`.criteria`: slope intervals, kernel counts,
comparisons, the ledger's columns) and, per model, the claims it makes of its tables with
their predictions read off the registry's properties: :mod:`.membranes` (the paper's ledger),
:mod:`.elastic` (plane strain), :mod:`.membranes3d` and :mod:`.membranes3d_studies` (the
contact face), :mod:`.elastic3d` (3D elastic bodies on the face); :mod:`.gate` checks the
ledger they make against its tables and predictions; :mod:`.tolerance` states a round-off-level
quantity against its tolerance (the ledger is the same text on every route and machine)."""
