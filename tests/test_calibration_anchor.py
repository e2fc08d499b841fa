"""The fit's Level I anchor rows (calibration/fit.py) compute the model's own elastic sphere."""

import dataclasses

import numpy as np

from spherecontact.calibration.fit import ANCHOR_WEIGHT, ELASTIC_SPHERE, level_I_anchor
from spherecontact.model import Material, Sphere, contact, load_coefficients


def test_anchor_rows_are_the_models_elastic_sphere_against_the_fe():
    m = Material.elastic(E=1000.0, nu=0.3)  # elastic
    flat = Sphere(np.inf, Material.rigid())
    h = np.array([p[0] for p in ELASTIC_SPHERE])
    target = np.array([p[1] for p in ELASTIC_SPHERE])
    other = dataclasses.replace(load_coefficients(), finite_size_H_bar=(0.5, -0.2),
                                finite_size_c2=(0.1, 0.4))
    for co in (load_coefficients(), other):
        F = contact(Sphere(1.0, m), flat, h, co).F
        ratio = F / (4.0 / 3.0 * m.E_prime * h**1.5)
        np.testing.assert_allclose(level_I_anchor(co), ANCHOR_WEIGHT * np.log(ratio / target), atol=1e-9)


def test_pure_hertz_misses_the_finite_sphere():
    # without finite-size terms Level I is Hertz, 2.2-5.7 % under the FE's elastic hemisphere
    co = dataclasses.replace(load_coefficients(), finite_size_H_bar=(), finite_size_c2=())
    r = level_I_anchor(co) / ANCHOR_WEIGHT
    np.testing.assert_allclose(r, -np.log([p[1] for p in ELASTIC_SPHERE]), rtol=1e-12)
    assert np.all(r < -0.02)
