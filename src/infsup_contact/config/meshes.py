"""The meshes of the workflow configuration and what runs on each: every mesh (pair) with its
cases and multiplier meshes (:func:`mesh_uses`), and the check that every space has a
multiplier on each of them (:func:`check_space_meshes`, a rule of
:data:`~infsup_contact.config.checks.CROSS_KEY_RULES`)."""
from __future__ import annotations

from .models import study_entries
from .schema import ConfigError
from ..errors import InputError


def scene_meshes(cfg) -> dict:
    """Scene name → its mesh sizes N (the scene's own ``N`` or ``contact.N``)."""
    cc = cfg["contact"]
    return {name: list(spec.get("N", cc["N"])) for name, spec in cc["scenes"].items()}


def mesh_uses(cfg, with_cases: bool = True):
    """Every mesh (pair) of the config with what runs on it: yields ``(key, value, N1, N2, cases
    by k, multiplier meshes)``; ``cases by k`` maps a degree to the case ids (or Rem 5.5 triples)
    run with it, as the stages run them (the elastic stages, every space of infsup.cases defined
    for k; the benchmarks, the paper's cases and the reference space; the figures, their cases). ``with_cases=False``: the
    meshes only ({} for the cases; no registry lookups, usable before the user spaces load)."""
    from ..discretization.spaces.registry import PAPER_CASES, REFERENCE_SPACE, ids_valid_for
    from ..discretization.gamma.mesh_series import FAMILY_RULES

    def by_k(cases: dict) -> dict:
        if not with_cases:
            return {}
        return {k: [c for c, ks in cases.items() if k in ks] for k in sorted({k for ks in cases.values() for k in ks})}

    def every(ks, ids=None) -> dict:
        if not with_cases:
            return {}
        return {k: ids_valid_for(k, ids if ids is not None else list(cfg["infsup"]["cases"])) for k in ks}

    ic, cc, bc = cfg["infsup"], cfg["contact"], cfg["benchmarks"]
    inf, mm = by_k(ic["cases"]), ic["multiplier_meshes"]
    for i, n in enumerate(ic["N"]):
        yield f"infsup.N[{i}]", n, n, n, inf, mm
    for i, pair in enumerate(ic.get("nonmatching", [])):
        yield f"infsup.nonmatching[{i}]", pair, *pair, inf, mm
    for name, n2s in ic.get("nonmatching_families", {}).items():
        for i, n2 in enumerate(n2s):
            yield f"infsup.nonmatching_families.{name}[{i}]", n2, FAMILY_RULES[name][0](n2), n2, inf, mm
    con = by_k(cc["cases"])
    for name, ns in scene_meshes(cfg).items():
        key = f"contact.scenes.{name}.N" if "N" in cc["scenes"][name] else "contact.N"
        for i, n in enumerate(ns):
            yield f"{key}[{i}]", n, n, n, con, ("omega2",)
    for at, ec in study_entries(cfg, "elastic"):
        for key, ks in (("N", {*ec["k"], *ec["nu_sweep_k"]}), ("nonmatching", ec["k"]),
                        ("patch_pairs", ec["patch_k"]), ("bench_N", ec["bench_k"])):
            for i, item in enumerate(ec[key]):
                n1, n2 = item if isinstance(item, list) else (item, item)
                yield f"{at}.{key}[{i}]", item, n1, n2, every(ks), ("omega2",)
        hz = ec["hertz"]
        for i, n in enumerate(hz["N"]):
            yield f"{at}.hertz.N[{i}]", n, n, n, every(hz["k"]), ("omega2",)
        yield (f"{at}.hertz.modeling_N", hz["modeling_N"], hz["modeling_N"], hz["modeling_N"],
               {2: [REFERENCE_SPACE]} if with_cases else {}, ("omega2",))
    for key, ks, ids in (("beta_N", bc["beta_k"], PAPER_CASES), ("contact_N", bc["contact_k"], [REFERENCE_SPACE])):
        for i, n in enumerate(bc[key]):
            yield f"benchmarks.{key}[{i}]", n, n, n, every(ks, ids), ("omega2",)
    fc = cfg["figures"]
    for name in ("contact_solutions", "dual"):
        fig = fc[name]
        yield (f"figures.{name}.N", fig["N"], fig["N"], fig["N"], {fig["k"]: list(fig["cases"])} if with_cases else {},
               ("omega2",))
    pairs = {}
    for case, k in fc["elastic_profiles"]["pairs"]:
        pairs.setdefault(k, []).append(case)
    n = fc["elastic_profiles"]["N"]
    yield "figures.elastic_profiles.N", n, n, n, pairs if with_cases else {}, ("omega2",)
    rem55 = {}
    if with_cases:
        from ..study.claims.membranes import REM55_INSTANCES

        for _, _, k, triple, _ in REM55_INSTANCES:
            rem55.setdefault(k, []).append(triple)
    for i, n in enumerate(cfg["claims"]["rem55_N"]):
        yield f"claims.rem55_N[{i}]", n, n, n, rem55, ("omega2",)


def config_intervals(cfg, limit: int = 1024) -> set:
    """Numbers of intervals of every multiplier mesh of the config (best effort: a config
    that is not yet validated may lack keys), for checking the user spaces on each."""
    from ..discretization.spaces.registry import MULTIPLIER_CHOICES, multiplier_intervals

    out = set()
    try:
        for _, _, n1, n2, _, _ in mesh_uses(cfg, with_cases=False):
            if all(isinstance(v, int) and not isinstance(v, bool) and 1 <= v <= limit for v in (n1, n2)):
                out |= {multiplier_intervals(n1, n2, c) for c in MULTIPLIER_CHOICES}
    except (LookupError, TypeError, ValueError, AttributeError, ArithmeticError):
        pass  # the schema names what is malformed
    return out


def check_space_meshes(cfg) -> None:
    """Every N list gets the minimum its spaces need: a case whose dim M_h is 0 on a mesh of
    the list (T3 and DUAL with k = 1 on N = 1) is refused, naming the key, the case and k."""
    from ..discretization.spaces.registry import case_name, is_empty, min_intervals, multiplier_intervals

    for key, value, n1, n2, cases_by_k, choices in mesh_uses(cfg):
        for k, cases in cases_by_k.items():
            for choice in choices:
                n = multiplier_intervals(n1, n2, choice)
                for case in cases:
                    try:
                        empty = is_empty(case, k, n)
                    except InputError as err:  # a user space failing on this N
                        raise ConfigError(key, f"case {case_name(case)} with k = {k} fails on N = {n} intervals "
                                          f"({err})", got=value) from None
                    if empty:
                        low = min_intervals(case, k)
                        where = (f"N = {n}" if n1 == n2 else f"the {choice} multiplier mesh of N1 = {n1}, N2 = {n2} "
                                 f"({n} interval{'s' if n != 1 else ''})")
                        raise ConfigError(key, f"case {case_name(case)} with k = {k} has dim M_h = 0 on {where}: "
                                          "nothing to compute", got=value,
                                          allowed=(f"N >= {low}" if n1 == n2 else
                                                   f"pairs whose {choice} multiplier mesh has >= {low} intervals"))
