"""The C99 evaluator ``dem/spherecontact_table.c`` against ``ContactLaw``: compiled here with the
system C compiler (strict C99, warnings as errors), loaded with ctypes, and compared on random
(h, h_max) covering loading, unloading, reloading, separation and both sides beyond the table."""

import ctypes
import shutil
import subprocess
import warnings
from pathlib import Path

import numpy as np
import pytest

from spherecontact.model import CalibrationRangeWarning, Material, Sphere
from spherecontact.model.dem_table import TableLaw, calibrated_law, read_table2, write_table2

DEM = Path(__file__).resolve().parents[1] / "dem"
STEEL = Material(E=210e9, nu=0.3, sigma_y=400e6, K=600e6, n=0.3)
ALU = Material(E=70e9, nu=0.33, sigma_y=100e6, K=200e6, n=0.5)
#: tolerance of the C evaluator against ContactLaw (of F_max near F = 0)
RTOL = 1e-9


def _compiler():
    for cc in ("cc", "gcc", "clang"):
        if shutil.which(cc):
            return cc
    return None


@pytest.fixture(scope="module")
def lib(tmp_path_factory):
    cc = _compiler()
    if cc is None:
        pytest.skip("no C compiler (cc, gcc or clang) on PATH to build dem/spherecontact_table.c")
    out = tmp_path_factory.mktemp("sct") / "libsct.so"
    subprocess.run([cc, "-std=c99", "-O2", "-Wall", "-Wextra", "-pedantic", "-Werror", "-shared",
                    "-fPIC", str(DEM / "spherecontact_table.c"), "-o", str(out), "-lm"], check=True)
    lib = ctypes.CDLL(str(out))
    lib.sct_load.restype = ctypes.c_void_p
    lib.sct_load.argtypes = [ctypes.c_char_p, ctypes.c_char_p, ctypes.c_size_t]
    lib.sct_free.argtypes = [ctypes.c_void_p]
    dp = ctypes.POINTER(ctypes.c_double)
    lib.sct_eval_many.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_double, ctypes.c_size_t,
                                  dp, dp, dp, dp, dp, dp]
    lib.sct_eval_many.restype = ctypes.c_int
    return lib


class _Table:
    def __init__(self, lib, path):
        self.lib = lib
        err = ctypes.create_string_buffer(512)
        self.ptr = lib.sct_load(str(path).encode(), err, 512)
        self.err = err.value.decode()

    def eval(self, R1, R2, h, hm):
        h, hm = np.ascontiguousarray(h, float), np.ascontiguousarray(hm, float)
        outs = [np.empty(h.size) for _ in range(4)]
        dp = ctypes.POINTER(ctypes.c_double)
        rc = self.lib.sct_eval_many(self.ptr, R1, R2, h.size, h.ctypes.data_as(dp), hm.ctypes.data_as(dp),
                                    *(o.ctypes.data_as(dp) for o in outs))
        return rc, outs

    def close(self):
        if self.ptr:
            self.lib.sct_free(self.ptr)


def _points(law, n, rng):
    """n random (h, h_max): a quarter each loading (h ≥ h_max), unloading within the elastic
    recovery, reloading/separated (h down to below zero), and peaks below or beyond the table."""
    q = n // 4
    lo, hi = np.log(law.h_min), np.log(law.h_max)
    hm = np.exp(rng.uniform(lo, hi, 3 * q))
    r = n - 3 * q
    beyond = np.where(np.arange(r) % 2 == 0, rng.uniform(lo - 3.0, lo, r), rng.uniform(hi, hi + 1.5, r))
    hm = np.concatenate([hm, np.exp(beyond)])                            # below and above
    rec = law._peaks(np.maximum(hm, law.h_min))[3]
    h = np.empty(n)
    h[:q] = hm[:q] * rng.uniform(1.0, 1.2, q)                            # loading, new peaks
    h[q:2 * q] = hm[q:2 * q] * (1.0 - rec[q:2 * q] * rng.uniform(0, 1, q))  # on the branch
    h[2 * q:3 * q] = hm[2 * q:3 * q] * rng.uniform(-0.2, 1.0, q)          # reloading, separated
    h[3 * q:] = hm[3 * q:] * rng.uniform(0.9, 1.1, n - 3 * q)             # beyond, both ways
    h[:8] = hm[:8]                                                        # exactly at the peak
    return h, hm


PAIRS = {"steel-alu": (Sphere(1e-3, STEEL), Sphere(2e-3, ALU), 100_000),
         "steel-steel": (Sphere(1e-3, STEEL), Sphere(1e-3, STEEL), 30_000),
         "steel-flat": (Sphere(1e-3, STEEL), Sphere(np.inf, Material.rigid()), 30_000)}


@pytest.mark.parametrize("name", list(PAIRS))
def test_c_evaluator_equals_contact_law(lib, tmp_path, name):
    s1, s2, n = PAIRS[name]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationRangeWarning)
        law = calibrated_law(s1, s2)
        write_table2(tmp_path / "t.sct", s1, s2, laws=[law])
        h, hm = _points(law, n, np.random.default_rng(11))
        F_ref, k_ref = law.force(h, hm)
        F_max = law.loading_force(np.maximum(h, hm).clip(min=law.h_min))[0]
        sub = slice(0, n, max(n // 3000, 1))  # the full state (a, h1) on a subset
        st = law(h[sub], hm[sub])
    tab = _Table(lib, tmp_path / "t.sct")
    assert tab.ptr, tab.err
    try:
        rc, (F, k, a, h1) = tab.eval(s1.radius, s2.radius, h, hm)
    finally:
        tab.close()
    assert rc == 0
    errF = np.abs(F - F_ref) / np.maximum(np.abs(F_ref), F_max)
    on = F_ref > 1e-6 * F_max  # stiffness relative where the contact carries load
    errk = np.abs(k - k_ref)[on] / np.abs(k_ref[on])
    print(f"{name}: {n} points, max rel. error F {errF.max():.2g}, dF/dh {errk.max():.2g}")
    assert errF.max() <= RTOL and errk.max() <= RTOL
    assert np.all((F == 0) == (F_ref == 0))
    # each kind of point was exercised
    assert (h > hm).sum() > n // 5 and ((h < hm) & (F_ref > 0)).sum() > n // 5
    assert (F_ref == 0).sum() > n // 50 and (hm > law.h_max).sum() > n // 20 and (hm < law.h_min).any()
    on = st.F > 0
    np.testing.assert_allclose(a[sub][on], st.a[on], rtol=RTOL)
    np.testing.assert_allclose(h1[sub][on], st.h1[on], rtol=RTOL, atol=RTOL * law.h_max)


def test_c_evaluator_ratio_range_and_errors(lib, tmp_path):
    """A ratio-range file: the C code follows the file's rule (TableLaw) at any ratio and size;
    bad inputs are refused with a message naming the problem."""
    s1 = Sphere(1e-3, STEEL)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationRangeWarning)
        write_table2(tmp_path / "r.sct", s1, Sphere(1e-3, ALU), ratios=np.geomspace(0.8, 1.25, 3),
                     h_max=2e-4, probes=1)
    tl = TableLaw.from_file(tmp_path / "r.sct")
    tab = _Table(lib, tmp_path / "r.sct")
    assert tab.ptr, tab.err
    rng = np.random.default_rng(2)
    try:
        for R1, ratio in ((1e-3, 0.8), (3e-4, 0.93), (2e-3, 1.2)):
            hm = np.exp(rng.uniform(np.log(1e-10), np.log(4e-4), 2000)) * R1 / 1e-3
            h = hm * rng.uniform(0.9, 1.05, hm.size)
            rc, (F, k, a, h1) = tab.eval(R1, ratio * R1, h, hm)
            assert rc == 0
            ref = tl.evaluate(h, hm, R1, ratio * R1)
            F_max = tl.evaluate(np.maximum(h, hm), np.maximum(h, hm), R1, ratio * R1)[0]
            assert np.max(np.abs(F - ref[0]) / F_max) <= RTOL
            np.testing.assert_allclose(a, ref[2], rtol=RTOL)
        assert tab.eval(1e-3, 1.3e-3, np.ones(1), np.ones(1))[0] == 3  # SCT_ERR_RATIO
        assert tab.eval(-1.0, 1.0, np.ones(1), np.ones(1))[0] == 4     # SCT_ERR_ARG
    finally:
        tab.close()
    # missing, foreign and corrupt files
    bad = _Table(lib, tmp_path / "missing.sct")
    assert not bad.ptr and "cannot open contact table" in bad.err and "missing.sct" in bad.err
    (tmp_path / "v1.sct").write_text("spherecontact-contact-table/1\n")
    bad = _Table(lib, tmp_path / "v1.sct")
    assert not bad.ptr and "is not a contact table of format spherecontact-contact-table/2" in bad.err
    lines = (tmp_path / "r.sct").read_text().splitlines()
    (tmp_path / "cut.sct").write_text("\n".join(lines[:30]) + "\n")
    bad = _Table(lib, tmp_path / "cut.sct")
    assert not bad.ptr and "corrupt" in bad.err and "node row" in bad.err
    body = [ln for ln in lines if not ln.startswith("end")]
    (tmp_path / "noend.sct").write_text("\n".join(body) + "\n")
    bad = _Table(lib, tmp_path / "noend.sct")
    assert not bad.ptr and "no 'end' line" in bad.err
    assert len(read_table2(tmp_path / "r.sct")["slices"]) == 3


class _Stencil(ctypes.Structure):
    _fields_ = [("n", ctypes.c_int), ("idx", ctypes.c_int * 4), ("w", ctypes.c_double * 4),
                ("lam", ctypes.c_double * 4), ("Rs", ctypes.c_double), ("h_elastic", ctypes.c_double)]


def test_c_largest_stiffness_bounds_the_law(lib, tmp_path):
    """sct_max_stiffness (for a critical time step) is at least every dF/dh of the law up to h_cap,
    loading or unloading, and sct_h_max is the table's end at the contact's size."""
    s1, s2 = Sphere(1e-3, STEEL), Sphere(2e-3, ALU)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationRangeWarning)
        law = calibrated_law(s1, s2)
        write_table2(tmp_path / "t.sct", s1, s2, laws=[law])
        hm = np.geomspace(1e-4 * law.h_max, law.h_max, 400)
        rec = law._peaks(hm)[3]
        h = np.concatenate([hm, hm * (1.0 - rec * 0.5)])
        k = law.force(h, np.concatenate([hm, hm]))[1]
    tab = _Table(lib, tmp_path / "t.sct")
    st = _Stencil()
    lib.sct_stencil_for.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_double,
                                    ctypes.POINTER(_Stencil), ctypes.c_char_p, ctypes.c_size_t]
    lib.sct_max_stiffness.argtypes = [ctypes.c_void_p, ctypes.POINTER(_Stencil), ctypes.c_double]
    lib.sct_max_stiffness.restype = ctypes.c_double
    lib.sct_h_max.argtypes = [ctypes.c_void_p, ctypes.POINTER(_Stencil)]
    lib.sct_h_max.restype = ctypes.c_double
    try:
        assert lib.sct_stencil_for(tab.ptr, 1e-3, 2e-3, ctypes.byref(st), None, 0) == 0
        kmax = lib.sct_max_stiffness(tab.ptr, ctypes.byref(st), law.h_max)
        assert lib.sct_h_max(tab.ptr, ctypes.byref(st)) == law.h_max
    finally:
        tab.close()
    assert kmax >= k.max() * (1.0 - 1e-12)
    assert kmax <= 1.5 * k.max()  # the bound is the law's, not a loose one


class _Result(ctypes.Structure):
    _fields_ = [("F", ctypes.c_double), ("dF_dh", ctypes.c_double), ("a", ctypes.c_double),
                ("h1", ctypes.c_double)]


def test_c_force_only_evaluation_equals_the_full_one(lib, tmp_path):
    """sct_eval_parts without a and h1 (what a frictionless code calls) gives the same F and dF/dh,
    to the bit, as the full evaluation, on loading, unloading and beyond the table, between the
    slices of a ratio-range table; the parts not asked for are 0."""
    s1, s2 = Sphere(1e-3, STEEL), Sphere(1e-3, ALU)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationRangeWarning)
        write_table2(tmp_path / "r.sct", s1, s2, ratios=np.geomspace(0.5, 2.0, 5), probes=1)
    lib.sct_stencil_for.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_double,
                                    ctypes.POINTER(_Stencil), ctypes.c_char_p, ctypes.c_size_t]
    lib.sct_eval_parts.argtypes = [ctypes.c_void_p, ctypes.POINTER(_Stencil), ctypes.c_double,
                                   ctypes.c_double, ctypes.c_int, ctypes.POINTER(_Result)]
    tab = _Table(lib, tmp_path / "r.sct")
    rng = np.random.default_rng(7)
    st, full, part = _Stencil(), _Result(), _Result()
    seen = {"loading": 0, "unloading": 0}
    try:
        for R2 in (0.6e-3, 1.3e-3, 1.9e-3):
            assert lib.sct_stencil_for(tab.ptr, 1e-3, R2, ctypes.byref(st), None, 0) == 0
            assert st.n == 4
            for hm in np.exp(rng.uniform(np.log(1e-9), np.log(5e-4), 60)):
                for h in (hm, 1.2 * hm, hm * (1 - 1e-3), hm * (1 - 1e-2)):
                    lib.sct_eval_parts(tab.ptr, ctypes.byref(st), h, hm, 3, ctypes.byref(full))
                    lib.sct_eval_parts(tab.ptr, ctypes.byref(st), h, hm, 0, ctypes.byref(part))
                    assert (part.F, part.dF_dh) == (full.F, full.dF_dh)
                    assert part.a == 0.0 and part.h1 == 0.0
                    if full.F > 0:
                        seen["loading" if h >= hm else "unloading"] += 1
    finally:
        tab.close()
    assert min(seen.values()) > 100
