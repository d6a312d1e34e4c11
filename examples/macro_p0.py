"""A multiplier space that is not built in: piecewise constants on pairs of intervals of G_h.

M_h = P_0 on the macro partition G_{2h} (an odd last interval joins the pair before it),
dim M_h = ⌊N/2⌋. Against continuous P_k traces this halves the multipliers of R5.4 (P_0 on
every interval, one zero mode for k = 1): the expectation stated below is that the pair is
stable for every k, which `infsup-contact verdict --space examples/macro_p0.py:space` checks.

Run it everywhere a case id is accepted:

    infsup-contact verdict --space examples/macro_p0.py:space --k 1
    infsup-contact beta --space examples/macro_p0.py:space --k 1 --N1 16 --N2 16
    infsup-contact contact --space examples/macro_p0.py:space --scene membranes --k 1 --N1 16 --N2 16

and in the workflow with `spaces: [examples/macro_p0.py:space]` and `P0-2h: [1, 2]` under
`infsup.cases` / `contact.cases` of the config.
"""
import numpy as np

from infsup_contact.discretization.segment.multipliers import local_basis_space
from infsup_contact.discretization.spaces.spec import SpaceSpec


def macro_p0(k, breakpoints):
    """P_0 on pairs of intervals: intervals 2m and 2m + 1 share one basis function."""
    n = len(breakpoints) - 1
    pair = np.minimum(np.arange(n) // 2, max(n // 2 - 1, 0))
    return local_basis_space(breakpoints, 0, pair[:, None])


def space():
    return SpaceSpec("P0-2h", paper_ref="user space", definition="M^0_0 on G_2h", build=macro_p0,
                     degree=lambda k: 0, expected="stable", dimension=lambda k, n: max(n // 2, 1))
