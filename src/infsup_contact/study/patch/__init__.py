"""The contact patch test, one for every model: two bodies pressed together across a
non-matching Γ with a uniform exact pressure, solved for every case of the registry (λ_h = λ and
u_h = u to round-off iff 1 ∈ M_h and K has no kernel). :mod:`.table` is the loop and kernel
count every model shares; the scenes: :mod:`.segment` (the 2D elastic blocks on the paper's
segment), :mod:`.face` (membranes on the 3D contact face, and the solve every face scene uses),
:mod:`.elastic3d` (elastic cubes on the face)."""
