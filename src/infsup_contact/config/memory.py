"""Does a config's largest job fit this machine? Every job of a config that computes, with
its memory estimate (:mod:`infsup_contact.resources`), against MemTotal — an error for a
local run (:func:`check_job_memory`) — and against MemAvailable — a note (:func:`memory_notes`).

``workflow/rules/common.smk`` runs both after :func:`~infsup_contact.config.checks.check_config`
accepted the config; a cluster job asks the scheduler for its own ``mem_mb`` instead.
"""
from __future__ import annotations

from .. import resources as R
from .checks import ConfigError
from .meshes import scene_meshes
from ..study.contact.registry import scene_spec


def job_estimates(cfg):
    """(config key that sets its size, job, estimate) of every job that computes: β_h and
    contact per mesh, the Rem 5.5 instances of claims_extra, the two bench stages."""
    ic, cc, bc = cfg["infsup"], cfg["contact"], cfg["benchmarks"]
    ks = sorted({k for klist in ic["cases"].values() for k in klist})
    from ..discretization.gamma.mesh_series import series_of_pairs

    for (n1, n2), names in series_of_pairs(ic).items():
        key = ("infsup.N" if "matching" in names else
               "infsup.nonmatching" if any(n.startswith("ratio") for n in names)
               else f"infsup.nonmatching_families.{names[0]}")
        for f in ic["families"]:
            for k in ks:
                yield key, f"beta_job {f} k={k} {n1}x{n2}", R.beta_estimate(
                    f, k, n1, n2, ic["multiplier_meshes"], ic["norms"])
    ck = sorted({k for klist in cc["cases"].values() for k in klist})
    for s, spec in cc["scenes"].items():
        n_ref = cc["reference_N"] if scene_spec(spec["kind"]).needs_reference else None
        for n in scene_meshes(cfg)[s]:
            for f in cc["families"]:
                for k in ck:
                    est = R.contact_estimate(f, k, n, n, n_ref, len(cc["cases"]))
                    alone = R.contact_estimate(f, k, n, n, None, len(cc["cases"]))
                    key = ("contact.reference_N" if n_ref and est.bytes > 2 * alone.bytes
                           else f"contact.scenes.{s}.N" if "N" in spec else "contact.N")
                    yield key, f"contact_job {s} {f} k={k} N={n}", est
    for n in cfg["claims"]["rem55_N"]:
        yield "claims.rem55_N", f"claims_extra N={n}", R.beta_estimate("structured", 3, n, n, norms=("H",))
    yield from _elastic_estimates(cfg)
    yield from _model_table_estimates(cfg)
    yield from _face_estimates(cfg)
    for what in ("beta", "contact"):
        yield (f"benchmarks.{what}_N", f"bench_{what}", R.bench_estimate(
            what, bc[f"{what}_N"], bc[f"{what}_k"], bc["repeats"], bc.get("eigsh_max_N"),
            bc.get("kkt_max_N", 64)))


def _elastic_estimates(cfg):
    """The jobs of the model table's ``elastic`` studies: one β job per (family, k), its largest pair
    (membranes alongside, smaller), the Hertz references, the benchmark and the patch test."""
    from .models import study_entries

    for at, ec in study_entries(cfg, "elastic"):
        for n1, n2 in [(n, n) for n in ec["N"]] + [tuple(p) for p in ec["nonmatching"]]:
            key = f"{at}.N" if n1 == n2 else f"{at}.nonmatching"
            for f in ec["families"]:
                for k in sorted(set(ec["k"]) | set(ec["nu_sweep_k"])):
                    yield key, f"elastic_beta_job {f} k={k} {n1}x{n2}", R.beta_estimate(
                        f, k, n1, n2, "omega2", ("H",), components=2)
        hz = ec["hertz"]
        for key, n, k in [(f"{at}.hertz.N_ref", hz["N_ref"], k + 1) for k in hz["k"]] + \
                [(f"{at}.hertz.modeling_N", hz["modeling_N"], 2)]:
            yield key, f"elastic_hertz k={k} N={n}", R.beta_estimate("structured", k, n, n, "omega2", ("L2",),
                                                                     components=2)
        for n in ec["bench_N"]:
            for k in ec["bench_k"]:
                yield f"{at}.bench_N", f"elastic_bench k={k} N={n}", R.beta_estimate(
                    "structured", k, n, n, "omega2", ("H",), components=2)
        for n1, n2 in ec["patch_pairs"]:
            for k in ec["patch_k"]:
                yield f"{at}.patch_pairs", f"elastic_patch k={k} {n1}x{n2}", R.beta_estimate(
                    "structured", k, n1, n2, "omega2", ("L2",), components=2)


def _face_estimates(cfg):
    """The β jobs of the model table's 3D face studies (``membranes3d``, ``elastic3d``): per element and k, each
    matching N (up to the element's ``max_N`` or ``l2_max_N``) and non-matching pair, with the estimate the
    command line checks (:func:`~infsup_contact.resources.beta_estimate`, ``dim = 3``)."""
    from ..models import MODELS
    from .models import study_entries

    for at, fc in study_entries(cfg, "membranes3d") + study_entries(cfg, "elastic3d"):
        if fc.get("model") not in MODELS:
            continue
        name = at.rpartition(".")[2]
        model = MODELS[fc["model"]]
        for element in fc["elements"]:
            caps = [(fc.get(cap) or {}).get(element) for cap in ("max_N", "l2_max_N")]  # l2: L² rows above max_N
            top = None if caps[0] is None else max(c for c in caps if c is not None)
            pairs = [(f"{at}.N", n, n) for n in fc["N"] if top is None or n <= top]
            pairs += [(f"{at}.nonmatching", *p) for p in fc.get("nonmatching", [])]
            for key, n1, n2 in pairs:
                for k in fc["k"]:
                    yield key, f"{name} beta {element} k={k} {n1}x{n2}", R.beta_estimate(
                        "structured", k, n1, n2, components=model.components, dim=3)


def _model_table_estimates(cfg):
    """The β jobs of the model table's ``beta`` studies (one per element and k: its largest pair)."""
    from ..models.user_models import model_named

    for name, entry in (cfg.get("studies") or {}).items():
        if entry.get("study") != "beta":
            continue  # the other studies' jobs are counted above
        model = model_named(entry["model"])
        for n1, n2 in [(n, n) for n in entry["N"]] + [tuple(p) for p in entry.get("nonmatching", [])]:
            key = f"studies.{name}.N" if n1 == n2 else f"studies.{name}.nonmatching"
            for k in entry["k"]:
                yield key, f"model_job {name} k={k} {n1}x{n2}", R.beta_estimate(
                    "structured", k, n1, n2, "omega2", tuple(entry.get("norms", ("H", "L2"))),
                    components=model.components, dim=model.dim)


def check_job_memory(cfg, limit: float | None) -> None:
    """A local run: refuse a config whose largest job cannot fit in this machine's memory
    (``limit``: MemTotal); on a cluster each job asks the scheduler for its mem_mb instead."""
    if limit is None:
        return
    key, job, est = max(job_estimates(cfg), key=lambda t: t[2].bytes)
    if est.bytes > limit:
        raise ConfigError(key, f"the {job} job would need {est.describe()}, more than this machine's "
                          f"{R.human_bytes(limit)} of memory", got=_value(cfg, key),
                          allowed="sizes whose jobs fit here; larger ones on a cluster (--profile profiles/slurm)")


def _value(cfg, key: str):
    node = cfg
    for part in key.split("."):
        if not isinstance(node, dict) or part not in node:
            return None
        node = node[part]
    return node


def memory_notes(cfg, available: float | None) -> list:
    """The largest job against the memory available now (a note, not an error)."""
    if available is None:
        return []
    key, job, est = max(job_estimates(cfg), key=lambda t: t[2].bytes)
    if est.bytes <= available:
        return []
    return [f"config key {key}: the largest job ({job}) needs {est.describe()}, more than the "
            f"{R.human_bytes(available)} available now (its mem_mb tells the scheduler)"]
