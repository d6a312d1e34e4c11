"""The criteria that turn β_h series into verdicts: the ledger's claims (:mod:`.claims`) and the
stability verdict of one space (:mod:`.stability`). Shared by the study, the verdict command and
the certification of foreign systems, so none of them imports another for its rules."""
