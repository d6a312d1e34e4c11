"""Small real tables of the elastic stage (tiny meshes, a few seconds), for the tests of the
elastic section (tests/models/test_elastic.py, tests/report/test_paper.py)."""
import functools


@functools.lru_cache(maxsize=1)
def small_elastic_tables() -> dict:
    """beta, sweep, patch, hertz, claims, speed as the workflow writes them, on tiny meshes."""
    import pandas as pd

    from infsup_contact.bench import bench_beta, bench_for
    from infsup_contact.study.beta.elastic import elastic_beta_rows, nu_sweep_rows
    from infsup_contact.study.claims.elastic import elastic_claims, hertz_claims, patch_claims
    from infsup_contact.study.contact.hertz import discretization_rows, modeling_rows
    from infsup_contact.study.patch.segment import patch_rows

    beta = elastic_beta_rows("structured", 1, [(2, 2), (3, 3), (4, 4), (3, 2), (6, 4), (9, 6)], cases=["T3", "R5.2"])
    sweep = pd.concat([nu_sweep_rows(k, [2, 3, 4], [0.3, 0.49, 0.499, 0.4999], cases=["T3"]) for k in (1, 2)])
    patch = pd.DataFrame(patch_rows(["T3", "T5"], [2], [(3, 2), (12, 8)]))
    hertz = pd.DataFrame(discretization_rows(["T3"], [1], [4, 8], 16, 1.0, 0.05)
                         + modeling_rows("T3", 2, 8, 1.0, [0.05, 0.1]))
    cfg = dict(slope_tolerance=0.15, beta_floor=0.001, confidence=0.95, fit_window=5)
    claims = pd.concat([elastic_claims(beta, sweep, cfg), patch_claims(patch), hertz_claims(hertz)])
    speed = pd.DataFrame(bench_beta(bench_for("elastic"), [2], [1, 2, 4], repeats=1))
    return dict(beta=beta, sweep=sweep, patch=patch, hertz=hertz, claims=claims, speed=speed)
