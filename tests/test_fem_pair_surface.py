"""fem.pair_surface: the corner/midside alternation of the contact surfaces."""

import numpy as np
import pytest
from fem_pair_surface import alternation, run_surfaces, second_differences

from spherecontact.data import Database


def test_a_smooth_surface_does_not_alternate_and_a_sawtooth_does():
    r = np.linspace(0.0, 0.3, 41)  # corner, midside, corner, …
    z = r**2 / 2.0
    assert np.allclose(second_differences(z), (r[1] - r[0]) ** 2)
    assert alternation(z) == pytest.approx(0.0, abs=1e-15)
    eps = 1e-4
    teeth = np.where(np.arange(r.size) % 2 == 0, eps, -eps)  # corners up by ε, midsides down
    assert alternation(z + teeth) == pytest.approx(-4 * eps, rel=1e-9)
    assert alternation(z + teeth, first_corner=False) == pytest.approx(4 * eps, rel=1e-9)
    with pytest.raises(ValueError, match="at least 4 nodes"):
        alternation(z[:3])


def test_stored_penalty_pairs_alternate_ten_times_more_than_exact_contact_pairs():
    """Campaign v1: the pair R₂ = 2R₁ of equal hardness (two-pass nodal penalty) against the pair
    with σY₂ = 3σY₁ (exact one-pass contact), both at h/R 0.3 on the default mesh."""
    db = Database("data/reference.h5")
    keys = {rec.case: rec.key for rec in db.records()}
    penalty = run_surfaces(db.run(keys["two-pp-E200-nu0.3-vs-R2"]))
    exact = run_surfaces(db.run(keys["two-pp-E200-nu0.3-vs-sy3"]))
    assert penalty["mesh_matches"] and exact["mesh_matches"]
    for body in ("body1", "body2"):
        assert abs(penalty[body]["alternation"]) > 1e-3
        assert abs(penalty[body]["alternation"]) > 10 * abs(exact[body]["alternation"])
    # corners pressed into each body on both
    assert np.sign(penalty["body1"]["alternation"]) == np.sign(penalty["body2"]["alternation"])
