"""fem.pair_surface: the corner/midside alternation of the contact surfaces."""

from pathlib import Path

import numpy as np
import pytest
from fem_pair_surface import alternation, run_surfaces, second_differences

from spherecontact.campaign.design import parse_campaign
from spherecontact.campaign.driver import run_campaign
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


V2 = Path(__file__).resolve().parents[1] / "data" / "reference_v2.h5"
#: campaign v2's pairs of equal yield stress: two-pass penalty at 3 Gauss points per edge
GAUSS_POINT_PAIRS = ("two-pp-E300-nu0.3-vs-E900-f0.003", "two-pp-E300-nu0.3-vs-E99.9")
#: campaign v2's exact-contact pairs at h/R_min 0.3 on the band's default floor
EXACT_PAIRS = ("two-pp-E300-nu0.3-vs-R2-sy2", "two-pp-E300-nu0.3-vs-R2-sy4", "two-pp-E300-nu0.3-vs-sy4",
               "two-pp-E200-nu0.3-vs-R3-sy2", "two-pp-E200-nu0.3-vs-sy5")


@pytest.fixture(scope="module")
def v2_surfaces():
    db = Database(V2)
    return {rec.case: run_surfaces(db.run(rec.key)) for rec in db.records() if "radius2" in rec.inputs}


def test_stored_v2_pairs_gauss_point_penalty_alternates_more_than_exact_contact(v2_surfaces):
    """Campaign v2, final states at h/R_min 0.3 (surface band): the Gauss-point penalty leaves a
    small sawtooth, corners pressed into both bodies and mostly into the softer one, about ten times
    that of exact contact on the same mesh (two-pp-E300-nu0.3-vs-E99.9 against …-vs-sy4)."""
    s = v2_surfaces
    assert len(s) == 10 and all(x["mesh_matches"] for x in s.values())  # band floors 0.0005–0.003 rebuilt
    for case, softer in zip(GAUSS_POINT_PAIRS, ("body1", "body2"), strict=True):  # the lower E
        stiffer = "body2" if softer == "body1" else "body1"
        alt = {b: s[case][b]["alternation"] for b in ("body1", "body2")}
        assert alt["body1"] < 0 and alt["body2"] < 0, case
        assert 5e-5 < -alt[softer] < 5e-4 and -alt[softer] > 3 * -alt[stiffer], case
    exact = [s[c][b]["alternation"] for c in EXACT_PAIRS for b in ("body1", "body2")]
    assert max(abs(a) for a in exact) < 2e-5
    # the slave (body 1, the lower σY) dips at its corners, the master's stand out a little
    assert all(s[c]["body1"]["alternation"] < 0 < s[c]["body2"]["alternation"] for c in EXACT_PAIRS)
    same_mesh = abs(s["two-pp-E300-nu0.3-vs-E99.9"]["body2"]["alternation"])
    assert same_mesh > 5 * abs(s["two-pp-E300-nu0.3-vs-sy4"]["body1"]["alternation"])


#: two pairs with R₂ = 2R₁ on a coarse mesh to h/R 0.03 (a few seconds each): equal hardness with
#: campaign v1's two-pass nodal penalty, and σY₂ = 3σY₁ with exact one-pass contact
NODAL_VS_EXACT = """
[defaults]
h_max = 0.03
mesh_density = 0.5
[[pairs]]
scene = "two_body"
E_over_sigma_y = 200
radius2 = 2
options = { penalty = 100 }
[[pairs]]
scene = "two_body"
E_over_sigma_y = 200
radius2 = 2
sigma_y2_over_sigma_y1 = 3
"""


def test_nodal_penalty_pairs_alternate_ten_times_more_than_exact_contact_pairs(tmp_path):
    """What campaign v1's stored pairs showed at h/R 0.3 (nodal penalty 1.2–3.9e-3 R, the exact
    pair of σY₂ = 3σY₁ 0.9–1.3e-4 R), on a small database written here: the two-pass nodal
    penalty presses the corners into both bodies, by ten times or more the alternation of exact
    contact (measured −6.4e-5 / −1.2e-4 R against ±1.8e-6 R)."""
    campaign = parse_campaign(NODAL_VS_EXACT)
    db_path = tmp_path / "pairs.h5"
    summary = run_campaign(campaign, db_path, workers=0)
    assert summary["total"]["converged"] == 2
    db = Database(db_path)
    keys = {rec.case: rec.key for rec in db.records()}
    penalty = run_surfaces(db.run(keys["two-pp-E200-nu0.3-vs-R2"]))
    exact = run_surfaces(db.run(keys["two-pp-E200-nu0.3-vs-R2-sy3"]))
    assert penalty["mesh_matches"] and exact["mesh_matches"]
    for body in ("body1", "body2"):
        assert penalty[body]["alternation"] < -3e-5
        assert abs(penalty[body]["alternation"]) > 10 * abs(exact[body]["alternation"])
