"""Fast per-pair table (ContactLaw) against the exact solve, and the ``model curve`` CLI."""

import argparse
import json
import math
import time

import numpy as np
import pytest

from spherecontact.model import Material, Sphere, contact
from spherecontact.model.cli import curve, register
from spherecontact.model.coefficients import LITERATURE, Coefficients, default_coefficients
from spherecontact.model.fast import ContactLaw, contact_table

CO = Coefficients.from_dict(LITERATURE)
STEEL = Material(E=210e9, nu=0.3, sigma_y=400e6, K=600e6, n=0.3)
ALU = Material(E=70e9, nu=0.33, sigma_y=100e6, K=200e6, n=0.5)
TAB = Material.from_table(E=110e9, nu=0.34, eps_p=[0.0, 0.02, 0.1, 0.5],
                          sigma=[150e6, 200e6, 260e6, 300e6])
R = 1e-3
PAIRS = {
    "equal": (Sphere(R, STEEL), Sphere(R, STEEL)),
    "dissimilar": (Sphere(R, STEEL), Sphere(2 * R, ALU)),
    "table": (Sphere(R, TAB), Sphere(3 * R, ALU)),
    "wall": (Sphere(R, ALU), Sphere(math.inf, Material.rigid())),
}


@pytest.mark.parametrize("name", PAIRS)
def test_table_error_is_bounded_against_exact_solve(name):
    s1, s2 = PAIRS[name]
    law = ContactLaw(s1, s2, coeffs=CO)
    assert law.monotone
    assert max(law.error["F"], law.error["a"], law.error["stiffness"]) <= 1e-6
    rng = np.random.default_rng(0)
    h = R * np.exp(rng.uniform(math.log(1e-9), math.log(0.5), 3000))
    h = np.concatenate([h, law.kinks, law.kinks * (1 + 1e-7), law.kinks * (1 - 1e-7)])
    ex, fa = contact(s1, s2, h, CO), law(h)
    rel = lambda f: np.max(np.abs(getattr(fa, f) / getattr(ex, f) - 1))  # noqa: E731
    assert rel("F") <= law.error["F"]
    assert rel("a") <= law.error["a"]
    assert rel("stiffness") <= law.error["stiffness"]
    assert np.max(np.abs(fa.h1 - ex.h1) / h) <= max(law.error["h1"], 1e-12)
    F, k = law.force(h)
    assert np.array_equal(F, fa.F) and np.array_equal(k, fa.stiffness)
    hs = np.sort(h)
    assert np.all(np.diff(law.force(hs)[0]) >= 0)


def test_setup_time_and_fallback_outside_table():
    s1, s2 = PAIRS["dissimilar"]
    ContactLaw(s1, s2, coeffs=CO)
    t0 = time.perf_counter()
    law = contact_table(s1, s2, h_max=0.2 * R, coeffs=CO)
    assert time.perf_counter() - t0 < 0.25  # target 50 ms; generous on a loaded machine
    h = np.array([-1.0, 0.0, 1e-16, 0.1 * R, 0.4 * R])
    F, k = law.force(h)
    ex = contact(s1, s2, h, CO)
    assert F[0] == 0.0 and F[1] == 0.0 and k[0] == 0.0
    assert np.allclose(F[2:], ex.F[2:], rtol=1e-6)
    assert np.allclose(law(h).a, ex.a, rtol=1e-6)
    assert np.ndim(law.force(1e-5)[0]) == 0


def test_bad_table_arguments():
    s1, s2 = PAIRS["equal"]
    with pytest.raises(ValueError, match="h_max"):
        ContactLaw(s1, s2, h_max=-1.0)
    with pytest.raises(ValueError, match="h_min < h_max"):
        ContactLaw(s1, s2, h_max=1e-6, h_min=1e-5)


def _parser():
    p = argparse.ArgumentParser()
    register(p.add_subparsers(dest="stage"))
    return p


def test_cli_curve_json_and_csv(tmp_path, capsys):
    p = _parser()
    args = p.parse_args(["model", "curve", "--E", "210e9", "--nu", "0.3", "--sigma-y", "400e6",
                         "--K", "600e6", "--n", "0.3", "--radius", "1e-3", "--E2", "70e9",
                         "--nu2", "0.33", "--sigma-y2", "100e6", "--radius2", "2e-3",
                         "--h-max", "1e-4", "--points", "5", "--json"])
    assert args.func(args) == 0
    out = json.loads(capsys.readouterr().out)
    # the source of the default set: "literature" until calibration writes data/coefficients.json
    assert len(out["F"]) == 5
    assert out["meta"]["coefficients_source"] == default_coefficients().source
    ref = contact(Sphere(1e-3, STEEL), Sphere(2e-3, Material(E=70e9, nu=0.33, sigma_y=100e6,
                                                            K=600e6, n=0.3)), 1e-4)
    assert out["F"][-1] == pytest.approx(float(ref.F), rel=1e-12)
    csv = tmp_path / "c.csv"
    # literature set (no finite-size terms): an elastic sphere on a rigid flat is exact Hertz;
    # the calibrated default adds the finite-sphere term, +0.4 a/R at this a/R = 0.1
    lit = tmp_path / "literature.json"
    lit.write_text(json.dumps(LITERATURE))
    args = p.parse_args(["model", "curve", "--E", "210e9", "--radius", "1e-3", "--E2", "inf",
                         "--radius2", "inf", "--h-max", "1e-5", "--out", str(csv),
                         "--coefficients", str(lit)])
    args.func(args)
    rows = [r for r in csv.read_text().splitlines() if not r.startswith("#")]
    assert rows[0] == "h,F,a,h1,h2,stiffness" and len(rows) == 51
    h, F = map(float, rows[-1].split(",")[:2])
    assert F == pytest.approx(4 / 3 * 210e9 / 0.91 * math.sqrt(1e-3) * h**1.5, rel=1e-9)


def test_cli_bad_input_is_value_error():
    p = _parser()
    args = p.parse_args(["model", "curve", "--E", "210e9", "--nu", "0.7", "--radius", "1e-3",
                         "--h-max", "1e-5"])
    with pytest.raises(ValueError, match="nu"):
        args.func(args)
    with pytest.raises(ValueError, match="h-max"):
        curve(Sphere(R, STEEL), Sphere(R, STEEL), -1.0)
