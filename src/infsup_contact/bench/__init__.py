"""Bench: speed measured as ratios in one run on one machine, written to ``results/benchmarks/``.

``harness`` (interleaved repeats, machine facts), ``beta_routes``, ``face_beta`` (the 3D β_h) and ``contact_routes`` (ours
against the floor, the limit and the peers of ``peers``), ``speed_accuracy`` (time against
error, the Pareto front). Top of the house: imports ``study``, ``solvers`` and below.
"""
from .beta_routes import bench_beta
from .face_beta import bench_face
from .contact_routes import bench_contact, tune_peer
from .harness import machine_info, run_interleaved, write_machine_info
from .speed_accuracy import fastest_for_accuracy, pareto_front, speed_accuracy_table

__all__ = ["bench_beta", "bench_face", "bench_contact", "tune_peer", "machine_info", "run_interleaved", "write_machine_info",
           "fastest_for_accuracy", "pareto_front", "speed_accuracy_table"]
