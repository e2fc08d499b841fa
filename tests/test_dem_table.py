"""Contact table v2 (``dem/FORMAT.md``): the file's rule is ``ContactLaw(beyond="table")``, scales
with size, and interpolates between radius ratios within its measured error."""

import warnings

import numpy as np
import pytest

from spherecontact.cli import main
from spherecontact.model import CalibrationRangeWarning, Material, Sphere, contact
from spherecontact.model.dem_table import (
    FORMAT,
    TableLaw,
    calibrated_law,
    read_table2,
    write_table2,
)
from spherecontact.model.fast import ContactLaw

STEEL = Material(E=210e9, nu=0.3, sigma_y=400e6, K=600e6, n=0.3)
ALU = Material(E=70e9, nu=0.33, sigma_y=100e6, K=200e6, n=0.5)


def _random_history(law, n, rng):
    """(h, h_max) on loading, unloading, reloading, below and beyond the table."""
    hm = np.exp(rng.uniform(np.log(0.1 * law.h_min), np.log(3.0 * law.h_max), n))
    h = hm * rng.uniform(-0.1, 1.3, n)  # h > h_max: loading past the old peak
    return h, np.maximum(hm, 0.0)


@pytest.mark.parametrize("s2", [Sphere(2e-3, ALU), Sphere(1e-3, STEEL), Sphere(np.inf, Material.rigid())],
                         ids=["steel-alu", "steel-steel", "steel-flat"])
def test_one_slice_file_is_the_fast_law_with_its_rule_beyond(tmp_path, s2):
    s1 = Sphere(1e-3, STEEL)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationRangeWarning)
        law = calibrated_law(s1, s2)
        meta = write_table2(tmp_path / "t.sct", s1, s2, laws=[law])
        tl = TableLaw.from_file(tmp_path / "t.sct")
        h, hm = _random_history(law, 4000, np.random.default_rng(5))
        F, k, a, h1 = tl.evaluate(h, hm, s1.radius, s2.radius)
        Fe, ke = law.force(h, hm)
        st = law(h, hm)
        F_peak = law.loading_force(np.maximum(np.maximum(h, hm), law.h_min))[0]
    assert meta["format"] == FORMAT and meta["slices"][0]["h_max"] == law.h_max
    np.testing.assert_allclose(F, Fe, rtol=0, atol=1e-12 * F_peak.max())
    assert np.all(np.abs(F - Fe) <= 1e-12 * F_peak)
    on = Fe > 0
    np.testing.assert_allclose(k[on], ke[on], rtol=1e-11)
    np.testing.assert_allclose(a[on], st.a[on], rtol=1e-11)
    np.testing.assert_allclose(h1[on], st.h1[on], rtol=1e-11, atol=1e-14 * law.h_max)
    # the stored reference evaluations are the rule's
    chk = read_table2(tmp_path / "t.sct")["checks"]
    got = tl.evaluate(chk[:, 2], chk[:, 3], chk[0, 0], chk[0, 1])
    np.testing.assert_allclose(np.column_stack(got), chk[:, 4:], rtol=1e-15)


def test_default_range_is_the_calibrated_range():
    s1, s2 = Sphere(1e-3, STEEL), Sphere(1e-3, STEEL)
    law = calibrated_law(s1, s2)
    free = ContactLaw(s1, s2, h_max=2.0 * law.h_max)
    assert law.h_max == pytest.approx(free.h_calibrated, rel=1e-12)


@pytest.mark.parametrize("lam", [1e-3, 7.0])
def test_size_scaling_of_the_model_and_of_the_table(tmp_path, lam):
    """F(λh; λR1, λR2) = λ²F(h; R1, R2), a(λh; …) = λa: the model has no length of its own, so one
    file serves every size with its ratio."""
    s1, s2 = Sphere(1e-3, STEEL), Sphere(2e-3, ALU)
    h = np.geomspace(1e-9, 3e-4, 40)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationRangeWarning)
        st = contact(s1, s2, h)
        sl = contact(Sphere(lam * 1e-3, STEEL), Sphere(lam * 2e-3, ALU), lam * h)
        np.testing.assert_allclose(sl.F, lam**2 * st.F, rtol=1e-10)
        np.testing.assert_allclose(sl.a, lam * st.a, rtol=1e-10)
        np.testing.assert_allclose(sl.h1, lam * st.h1, rtol=1e-10)
        write_table2(tmp_path / "t.sct", s1, s2)
        tl = TableLaw.from_file(tmp_path / "t.sct")
        hm = np.full(h.size, 3e-4)
        F, k, a, _ = tl.evaluate(h, hm, 1e-3, 2e-3)
        Fs, ks, as_, _ = tl.evaluate(lam * h, lam * hm, lam * 1e-3, lam * 2e-3)
    np.testing.assert_allclose(Fs, lam**2 * F, rtol=1e-12)
    np.testing.assert_allclose(ks, lam * k, rtol=1e-12)
    np.testing.assert_allclose(as_, lam * a, rtol=1e-12)


def test_ratio_range_interpolates_within_its_measured_error(tmp_path):
    """A table over R2/R1 ∈ [0.7, 1.4]: exact at its slices, and between them within the error it
    measured and stored (≤ 0.5 % of F); checked again here at ratios it did not probe."""
    s1, s2 = Sphere(1e-3, STEEL), Sphere(1e-3, ALU)
    ratios = np.geomspace(0.7, 1.4, 5)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationRangeWarning)
        meta = write_table2(tmp_path / "r.sct", s1, s2, ratios=ratios)
        tl = TableLaw.from_file(tmp_path / "r.sct")
        err = meta["ratio_interpolation_error"]
        assert err["F_loading"] <= 5e-3 and err["F_unloading"] <= 5e-3
        worst = 0.0
        for r in (0.77, 1.23):
            ex = calibrated_law(s1, Sphere(r * 1e-3, ALU))
            hm = np.geomspace(1e-5 * ex.h_max, ex.h_max, 50)
            F = tl.evaluate(hm, hm, 1e-3, r * 1e-3)[0]
            worst = max(worst, float(np.max(np.abs(F / ex.loading_force(hm)[0] - 1.0))))
        # at a slice, the slice's own law
        law = ContactLaw(s1, Sphere(ratios[2] * 1e-3, ALU), h_max=meta["slices"][2]["h_max"],
                         beyond="table")
        h = np.geomspace(1e-9, law.h_max, 30)
        np.testing.assert_allclose(tl.evaluate(h, h, 1e-3, ratios[2] * 1e-3)[0],
                                   law.loading_force(h)[0], rtol=1e-12)
    assert worst <= 2.0 * err["F_loading"]
    with pytest.raises(ValueError, match=r"radius ratio R2/R1 = 1\.5 is outside the table's range"):
        tl.evaluate(1e-5, 1e-5, 1e-3, 1.5e-3)


def test_cli_writes_v2_and_refuses_bad_input(tmp_path, capsys):
    base = ["model", "table", "--E", "210e9", "--sigma-y", "400e6", "--K", "600e6", "--n", "0.3",
            "--radius", "1e-3"]
    assert main([*base, "--out", str(tmp_path / "eq.sct")]) == 0
    assert "1 slice(s)" in capsys.readouterr().out
    tab = read_table2(tmp_path / "eq.sct")
    assert tab["meta"]["format"] == FORMAT and len(tab["slices"]) == 1
    assert tab["slices"][0]["ratio"] == 1.0
    assert main([*base, "--ratio-range", "1", "2", "--slices", "2", "--h-max", "1e-4", "--out",
                 str(tmp_path / "r.sct")]) == 0
    assert "ratio-interpolation error" in capsys.readouterr().out
    assert main([*base, "--ratio-range", "2", "1", "--out", str(tmp_path / "bad.sct")]) == 2
    assert "--ratio-range LO HI needs finite 0 < LO < HI" in capsys.readouterr().err
    assert main([*base, "--slices", "3", "--out", str(tmp_path / "bad.sct")]) == 2
    assert main([*base, "--ratio-range", "1", "2", "--out", str(tmp_path / "bad.npz")]) == 2
    assert not (tmp_path / "bad.sct").exists() and not (tmp_path / "bad.npz").exists()
    bad = tmp_path / "corrupt.sct"
    bad.write_text("spherecontact-contact-table/1\n")
    with pytest.raises(ValueError, match="not a spherecontact-contact-table/2 file"):
        read_table2(bad)
    text = (tmp_path / "eq.sct").read_text().splitlines()
    bad.write_text("\n".join(text[:40]) + "\n")  # truncated inside the node rows
    with pytest.raises(ValueError, match="slice 0"):
        read_table2(bad)
