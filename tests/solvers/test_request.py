"""A β_h request's mesh options: typed, the side cache's key as they are, checked by one rule
that the command line, the request and the config share."""
import pytest

from infsup_contact.config.membranes3d import check_element
from infsup_contact.config.schema import ConfigError
from infsup_contact.errors import InputError
from infsup_contact.models import MODELS
from infsup_contact.models.membranes import MEMBRANES
from infsup_contact.solvers.request import (NO_OPTIONS, BetaRequest, MeshOptions, check_mesh_option, options_of,
                                            resolve_gamma)
from infsup_contact.solvers.side_cache import SideCache, side_keys

FACE_MODEL = MODELS["membranes3d"]


class _Recording:
    """A model that records the keywords its mesh builder is called with."""

    name = "recording"

    def __init__(self):
        self.calls = []

    def side_operator(self, mesh, k):
        return MEMBRANES.side_operator(mesh, k)

    def subdomain_mesh(self, family, n, side, **mesh_kwargs):
        self.calls.append(mesh_kwargs)
        return MEMBRANES.subdomain_mesh(family, n, side, **mesh_kwargs)


def test_options_equal_as_values_are_one_key():
    """An option left unset and one set to None are the builder's default alike: one key."""
    assert side_keys(MEMBRANES, "perturbed", 2, 5, 4, MeshOptions(seed=None)) == side_keys(
        MEMBRANES, "perturbed", 2, 5, 4, NO_OPTIONS)
    assert side_keys(MEMBRANES, "perturbed", 2, 5, 4, MeshOptions(seed=1, alpha=0.2))[1][-2] == MeshOptions(
        alpha=0.2, seed=1)


def test_the_cache_hands_the_set_options_to_the_model_as_keywords():
    model = _Recording()
    SideCache().pair(model, "perturbed", 1, 3, 2, MeshOptions(seed=4, alpha=0.1))
    assert model.calls == [{"seed": 4, "alpha": 0.1}] * 2
    SideCache().pair(model, "structured", 1, 3, 2)
    assert model.calls[2:] == [{}, {}]


def test_a_request_checks_the_model_s_declared_mesh_option():
    with pytest.raises(InputError) as err:
        BetaRequest("structured", 1, 2, 2, ("T3",), model=FACE_MODEL, mesh=MeshOptions(element="prism"))
    allowed = ", ".join(dict(FACE_MODEL.mesh_options)["element"])
    assert (err.value.key, err.value.allowed, err.value.got) == ("element", allowed, "prism")


def test_a_request_takes_mesh_options_only_typed():
    with pytest.raises(TypeError, match="MeshOptions"):
        BetaRequest("structured", 1, 2, 2, ("T3",), mesh={"element": "hex"})


def test_the_config_refuses_an_element_by_the_request_s_rule_naming_its_key():
    with pytest.raises(InputError) as request_err:
        check_mesh_option(FACE_MODEL, "element", "prism")
    with pytest.raises(ConfigError) as config_err:
        check_element("face.elements[1]", FACE_MODEL, "prism")
    text = str(config_err.value)
    assert text.startswith("config key face.elements[1]: not an element of membranes3d")
    assert f"allowed {request_err.value.allowed})" in text and "got 'prism'" in text
    for element in dict(FACE_MODEL.mesh_options)["element"]:
        check_element("face.elements[0]", FACE_MODEL, element)


@pytest.mark.parametrize("alpha, seed", [(0.5, 1), (0.1, -1), (float("nan"), None), (None, 2.5)])
def test_a_perturbed_request_refuses_what_its_mesh_builder_would(alpha, seed):
    """The mesh builder trusts a validated request (``SideCache.pair(..., checked=True)``), so the
    request refuses the perturbed family's seed and α itself: the builder's own error, key and words."""
    from infsup_contact.discretization.segment import meshes

    given = {key: v for key, v in (("alpha", alpha), ("seed", seed)) if v is not None}
    with pytest.raises(InputError) as builder:
        meshes.subdomain_mesh("perturbed", 2, 1, **given)
    with pytest.raises(InputError) as request:
        BetaRequest("perturbed", 1, 2, 2, ("T3",), mesh=MeshOptions(**given))
    assert (request.value.key, request.value.allowed, request.value.got) == (
        builder.value.key, builder.value.allowed, builder.value.got)


def test_mesh_options_are_the_builder_s_own_and_gamma_is_the_request_s():
    """Γ is a value of the request, not a mesh option: MeshOptions has no gamma, radius or
    coupling; the command line's Γ keys resolve to the request's own ``gamma`` (no mesh built)."""
    assert not {"gamma", "radius", "coupling"} & set(MeshOptions.__dataclass_fields__)
    mesh, gamma = options_of(MEMBRANES, gamma="arc", radius=2.0, coupling="projection")
    assert mesh == NO_OPTIONS and (gamma.radius, gamma.coupling) == (2.0, "projection")
    request = BetaRequest("structured", 1, 3, 2, ("T3",), mesh=mesh, gamma=gamma)
    assert request.gamma is gamma and request.interface is gamma
    flat = BetaRequest("structured", 1, 3, 2, ("T3",))
    assert flat.gamma is None and flat.interface == MEMBRANES.gamma()  # the model's flat Γ
    assert options_of(MEMBRANES) == (NO_OPTIONS, None)
    with pytest.raises(TypeError, match="gamma"):  # an unresolved name is a caller's slip
        BetaRequest("structured", 1, 3, 2, ("T3",), gamma="arc")


def test_a_sweep_over_two_gammas_shares_no_side():
    """The request's Γ is part of the side cache's key: two radii (or a radius and the flat Γ)
    never hand out each other's side, though the mesh options are equal."""
    arcs = [resolve_gamma(MEMBRANES, gamma="arc", radius=r, coupling="exact") for r in (2.0, 4.0)]
    keys = [side_keys(MEMBRANES, "structured", 1, 3, 2, NO_OPTIONS, g) for g in (None, *arcs)]
    for side in (0, 1):
        assert len({k[side] for k in keys}) == 3
    sides = [SideCache().pair(MEMBRANES, "structured", 1, 3, 2, gamma=g)[1] for g in (None, *arcs)]
    assert [s.trace.gamma for s in sides] == [MEMBRANES.gamma(), *arcs]  # each side built on its own Γ
