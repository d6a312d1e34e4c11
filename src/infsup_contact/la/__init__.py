"""The fast layer: the linear-algebra back ends, named for what they are.

``schur`` (one factorization of a body, Γ last, and its Schur complement / Steklov inverse),
``pardiso`` (MKL PARDISO's partial factorization), ``ordering`` (the Γ-last nested dissection
SuperLU is given), ``bottom`` (the bottom of a spectrum: shift-invert Lanczos, block inverse
iteration), ``reflection`` (a pencil split by commuting reflections), ``face_parity`` (the
face's H Gram series in its four parity blocks), ``exponential_sum`` (1/√x as a sum of
exponentials), ``richardson`` (the extrapolated series and its stopping bound), ``threaded``
(the products the libraries leave on one core), ``mkl`` and ``openblas`` (the libraries,
loaded and sized). Imports ``errors`` only.

The generic path reaches it through one seam per use: β_h (:mod:`infsup_contact.solvers.infsup`)
through the route of each space (:mod:`infsup_contact.solvers.routes`), a model's side
through :func:`infsup_contact.models.contract.factorized_side`.
"""
