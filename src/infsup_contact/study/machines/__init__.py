"""The machine paths: the same checks under every code path of both BLAS libraries, and their
ledgers compared byte for byte."""
