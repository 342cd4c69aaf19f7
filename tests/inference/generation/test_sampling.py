"""inference.generation.sampling: new curves from a latent prior through the real (untrained) decoder — item i decided
by
(seed, i) alone, so pages of a sequence are the curves of one larger request; N(0, I) latents as drawn by item i's own
generator; what counts as a plausible curve (finite, simple, inside the disc); and the priors a request may name."""

import numpy as np
import pytest

from curve_vae.inference.errors import InputError
from curve_vae.inference.generation.sampling import Sampler, fresh_seed

CENTER = np.array([64.0, 64.0])


@pytest.fixture(scope="module")
def sampler(runtime) -> Sampler:
    # the fixture model ships a learned prior (prior.npz)
    return runtime.sampler


@pytest.fixture(scope="module")
def no_prior(runtime) -> Sampler:
    return Sampler(runtime.graphs, None, CENTER, 64.0)


@pytest.mark.parametrize("valid", [False, True], ids=["any", "valid only"])
@pytest.mark.parametrize("prior", ["learned", "standard"])
def test_a_page_of_a_sequence_is_those_items_of_the_whole(sampler, prior, valid):
    whole = sampler.draw(6, seed=11, prior=prior, valid=valid)
    page = sampler.draw(2, seed=11, prior=prior, valid=valid, offset=3)
    np.testing.assert_array_equal(page.latents, whole.latents[3:5])
    np.testing.assert_array_equal(page.decoded, whole.decoded[3:5])
    np.testing.assert_array_equal(page.ctrl, whole.ctrl[3:5])
    assert page.prior == whole.prior == prior


def test_standard_latents_are_each_items_own_normal_draws_scaled_by_the_temperature(sampler, runtime):
    drawn = sampler.draw(4, seed=5, prior="standard", temperature=0.5, valid=False)
    want = np.stack([np.random.default_rng([5, i]).standard_normal(32) * 0.5 for i in range(4)])
    np.testing.assert_allclose(drawn.latents, want, rtol=1e-15)
    out, ctrl, _ = runtime.graphs.decode(want)
    np.testing.assert_array_equal(drawn.decoded, out)  # decoded in the model plane, as the decoder gives them
    np.testing.assert_array_equal(drawn.ctrl, ctrl)
    assert drawn.params is None and drawn.rejected == drawn.invalid == 0


def test_without_validity_nothing_is_rejected_and_with_one_draw_the_implausible_stay_invalid(sampler):
    loose = sampler.draw(8, seed=2, prior="standard", temperature=3.0, valid=False)
    judged = sampler.plausible(loose.decoded.astype(np.float64))
    once = sampler.draw(8, seed=2, prior="standard", temperature=3.0, max_draws=1)
    # the same first draws, judged: no second chance, so exactly the implausible ones are reported invalid
    assert once.rejected == 0 and once.invalid == int((~judged).sum())
    np.testing.assert_array_equal(once.latents, loose.latents)


def test_rejected_draws_are_counted_and_redrawn(sampler):
    loose = sampler.draw(8, seed=2, prior="standard", temperature=3.0, valid=False)
    bad = int((~sampler.plausible(loose.decoded.astype(np.float64))).sum())
    retried = sampler.draw(8, seed=2, prior="standard", temperature=3.0, max_draws=4)
    assert retried.rejected >= bad  # every implausible first draw was drawn again at least once
    assert retried.rejected <= 8 * 3 and retried.invalid <= bad
    keep = sampler.plausible(loose.decoded.astype(np.float64))
    np.testing.assert_array_equal(retried.latents[keep], loose.latents[keep])  # a good first draw is kept


def _arc(center, radius: float) -> np.ndarray:
    t = np.linspace(0, np.pi, 161)
    return np.stack([center[0] + radius * np.cos(t), center[1] + radius * np.sin(t)], axis=1)


PLAUSIBLE = {
    "inside the disc": (_arc(CENTER, 40.0), True),
    "just inside its edge": (_arc(CENTER, 49.999), True),
    "past its edge": (_arc(CENTER, 50.5), False),
    "shifted out": (_arc(CENTER + [30.0, 0.0], 40.0), False),
    "crossing itself": (np.array([[40.0, 40.0], [80.0, 80.0], [80.0, 40.0], [40.0, 80.0]]), False),
    "not finite": (np.where(np.arange(161)[:, None] == 80, np.nan, _arc(CENTER, 40.0)), False),
}


@pytest.mark.parametrize("curve, ok", PLAUSIBLE.values(), ids=PLAUSIBLE.keys())
def test_a_plausible_curve_is_finite_simple_and_inside_the_disc(runtime, curve, ok):
    s = Sampler(runtime.graphs, None, CENTER, 50.0)
    assert s.plausible(curve[None]).tolist() == [ok]


def test_the_priors_a_request_may_name(sampler, no_prior):
    assert sampler.names == ["learned", "standard"] and no_prior.names == ["standard"]
    assert sampler.draw(1, seed=0, valid=False).prior == "learned"  # the default where the model ships one
    assert no_prior.draw(1, seed=0, valid=False).prior == "standard"  # and N(0, I) where it does not


@pytest.mark.parametrize(
    "which, prior, message",
    [
        ("no_prior", "learned", "this model ships no learned prior"),
        ("sampler", "mine", "no prior named 'mine' on this server; it has: learned, standard"),
        ("no_prior", "mine", "no prior named 'mine' on this server; it has: standard"),
    ],
    ids=["learned, none shipped", "unknown", "unknown, none shipped"],
)
def test_a_prior_that_is_not_there_is_refused_naming_the_field(request, which, prior, message):
    with pytest.raises(InputError, match=message) as caught:
        request.getfixturevalue(which).draw(1, seed=0, prior=prior)
    assert caught.value.loc == ("prior",)


def test_fresh_seeds_are_exact_in_json_and_differ():
    seeds = {fresh_seed() for _ in range(20)}
    assert len(seeds) == 20  # 53 random bits: a repeat in 20 would be a broken generator
    assert all(isinstance(s, int) and 0 <= s < 2**53 for s in seeds)
