"""Speed–accuracy points: errors of every contact (scene, case, k, N) with the median wall
time of ``solve_contact`` for that discretization (timed on one scene), Pareto fronts marked."""
import sys

sys.path.insert(0, "workflow/scripts")
from _glue import add_provenance, limit_threads, log_to, read_table, register_user_spaces  # noqa: E402

limit_threads(1)  # timings are single-thread; the rule takes all cores to run alone
log_to(snakemake.log[0])  # noqa: F821
register_user_spaces(snakemake.config)  # noqa: F821


from infsup_contact.bench import machine_info, speed_accuracy_table  # noqa: E402
from infsup_contact.io import write_csv_atomic  # noqa: E402

cc, p = snakemake.params.cc, snakemake.params  # noqa: F821
spec = cc["scenes"].get(p.scene, {"kind": p.scene})
kind = spec["kind"]
params = {key: v for key, v in spec.items() if key not in ("kind", "N")}
errors = read_table(snakemake.input.contact, "contact")  # noqa: F821
print(f"machine: {machine_info()}", file=sys.stderr)
table = speed_accuracy_table(errors, repeats=int(p.repeats), timing_scene=kind,
                             timing_params=params, c=tuple(cc["c"]), budget=float(p.budget))
table["timing_scene"] = p.scene
write_csv_atomic(snakemake.output[0], add_provenance(table, {"contact": cc, "repeats": p.repeats,  # noqa: F821
                                                            "budget": p.budget,
                                                            "scene": p.scene}))
front = table[table.pareto_energy][["scene", "case", "k", "N", "seconds", "energy_error"]]
print("Pareto front (energy):\n" + front.to_string(), file=sys.stderr)
