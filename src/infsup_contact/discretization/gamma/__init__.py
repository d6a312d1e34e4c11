"""What every Γ shares: the :class:`~.interface.Interface`, the :class:`~.protocol.MultiplierSpace`
protocol, a side's trace, the coupling b(v, μ), Gauss rules, basis symmetries, "is 1 ∈ M_h?" and
the mesh series of the β_h study. Imports nothing of ``segment``, ``face`` or ``spaces``."""
