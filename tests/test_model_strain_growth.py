"""Representative strain growing with the depth of the contact, ε_rep = β x (1 + γ x)
(``beta_growth``; ``model.single.representative_strain``): exact slopes, the seed's form at
γ = 0, older files read unchanged, bad values named."""

import json
import math

import numpy as np
import pytest
from _slopes import assert_body_log_slopes

from spherecontact.model import Material, Sphere, contact, default_coefficients
from spherecontact.model.coefficients import LITERATURE, Coefficients
from spherecontact.model.single import BodyLaw, representative_strain

CO = default_coefficients()
LUDWIK = Material(E=500.0, nu=0.3, sigma_y=1.0, K=4.0, n=0.4)
TABLE = Material.from_table(E=300.0, nu=0.3, eps_p=[0.0, 0.05, 0.2, 1.0, 3.0],
                            sigma=[1.0, 1.6, 2.2, 3.0, 3.4])
FLAT = Sphere(math.inf, Material.rigid())


def _with_growth(co: Coefficients, g: float) -> Coefficients:
    return co.replace(beta_growth=g)


def test_strain_and_its_log_slope():
    co = _with_growth(CO, 5.0)
    x = np.array([1e-3, 0.1, 0.5, 1.0])
    eps, g = representative_strain(x, co.beta, co.beta_growth)
    np.testing.assert_allclose(eps, co.beta * x * (1 + 5.0 * x))
    e = 1e-7
    fd = np.log(representative_strain(x * (1 + e), co.beta, co.beta_growth)[0] / eps) / e
    np.testing.assert_allclose(g, fd, rtol=1e-5)
    # γ = 0 is the seed's ε_rep = β x, with slope 1
    eps0, g0 = representative_strain(x, CO.beta)
    np.testing.assert_allclose(eps0, CO.beta * x)
    np.testing.assert_array_equal(g0, 1.0)


@pytest.mark.parametrize("material", [LUDWIK, TABLE], ids=["ludwik", "table"])
def test_body_log_slopes_stay_exact_with_growth(material):
    law = BodyLaw(material, _with_growth(CO, 6.0))
    x = np.geomspace(0.01, 0.9, 37) * (1 + 1e-3)   # off the table's kinks
    for z in (0.0, 1.0):
        assert_body_log_slopes(law, x, x, z)


def test_growth_raises_the_flow_stress_only_where_the_contact_is_deep():
    s1 = Sphere(1.0, LUDWIK)
    h = np.array([1e-4, 0.2])
    lo = contact(s1, FLAT, h, _with_growth(CO, 0.0)).F
    hi = contact(s1, FLAT, h, _with_growth(CO, 5.0)).F
    assert abs(hi[0] / lo[0] - 1) < 0.02 < hi[1] / lo[1] - 1


def test_files_without_the_key_read_as_the_seed_form_and_write_no_key():
    d = json.loads(json.dumps(LITERATURE))
    assert "beta_growth" not in d
    co = Coefficients.from_dict(d)
    assert co.beta_growth == 0.0 and "beta_growth" not in co.to_dict()
    again = Coefficients.from_dict(_with_growth(co, 2.5).to_dict())
    assert again.beta_growth == 2.5


@pytest.mark.parametrize("bad", [-1.0, 101.0, "4", math.nan])
def test_bad_growth_is_named(bad):
    d = json.loads(json.dumps(LITERATURE))
    d["beta_growth"] = bad
    with pytest.raises(ValueError, match="beta_growth"):
        Coefficients.from_dict(d)


def test_level_I_follows_the_fe_elastic_sphere_within_half_a_percent():
    """Issue target: the shipped model's elastic sphere on a flat against the FE's elastic
    hemisphere (``make verify-fem``, F/Hertz at h/R = 0.002, 0.005, 0.01)."""
    from pathlib import Path

    fe = json.loads((Path(__file__).resolve().parents[1] / "reports" / "fem" /
                     "fem_verification.json").read_text())["hertz"]["F_over_Hertz_at_h"]
    m = Material.elastic(E=1000.0, nu=0.3)   # elastic: σ_Y = inf
    h = np.array([float(k) for k in fe])
    F = contact(Sphere(1.0, m), FLAT, h).F
    hertz = 4.0 / 3.0 * m.E_prime * h**1.5
    np.testing.assert_allclose(F / hertz, [fe[k] for k in fe], rtol=0.005)


def test_level_I_anchor_rows_are_the_fe_report_s_figures():
    """calibration.fit.ELASTIC_SPHERE copies F/Hertz of the FE elastic hemisphere from
    ``make verify-fem``'s report: a re-run that moves them must move the anchor too."""
    from pathlib import Path

    from spherecontact.calibration.fit import ELASTIC_SPHERE

    fe = json.loads((Path(__file__).resolve().parents[1] / "reports" / "fem" /
                     "fem_verification.json").read_text())["hertz"]["F_over_Hertz_at_h"]
    assert [h for h, _ in ELASTIC_SPHERE] == [float(k) for k in fe]
    np.testing.assert_allclose([v for _, v in ELASTIC_SPHERE], [fe[k] for k in fe], rtol=1e-6)
