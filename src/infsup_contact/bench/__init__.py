"""Bench: speed measured as ratios in one run on one machine, written to ``results/benchmarks/``.

``harness`` (interleaved repeats, machine facts), ``beta_bench`` (β_h of any model against its
limit) with what differs per model in ``beta_models`` (the membranes' pencil routes in
``beta_pencil``, the face's Schur routes in ``face_schur``), ``contact_routes`` (ours against the
floor, the limit and the peers of ``peers``), ``speed_accuracy`` (time against error, the Pareto
front), ``estimates`` (``--dry-run``'s estimates against measured runs). Top of the house: imports ``study``, ``contact``, ``solvers`` and below.
"""
from .beta_bench import bench_beta
from .beta_models import bench_for
from .contact_routes import bench_contact, tune_peer
from .harness import machine_info, run_interleaved, write_machine_info
from .speed_accuracy import fastest_for_accuracy, pareto_front, speed_accuracy_table

__all__ = ["bench_beta", "bench_for", "bench_contact", "tune_peer", "machine_info", "run_interleaved",
           "write_machine_info", "fastest_for_accuracy", "pareto_front", "speed_accuracy_table"]
