"""The contact scenes: loads with known answers, their registry, one solve → one tidy row, accuracy
measures, Γ profiles and convergence rates."""
