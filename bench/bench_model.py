"""Throughput of the closed-form model: F and dF/dh for 1e6 contacts, one core.

Cases: equal pair (exact, no κ solve), dissimilar pair (exact, nested κ solve),
fast path (``ContactLaw`` table: setup time and throughput), and the explicit
Jackson & Green (2005) formula on the same array as a cost reference.
Approaches are log-uniform in [1e-6 R, 0.3 R]. Times are the best of ``REPEAT`` runs.

``fast_with_history``: the fast path with a per-contact history (``force(h, h_max)``) for the
dissimilar pair: every contact loading (h = h_max), every contact on its unloading branch
(h_max 1–1.3 h), half and half — the DEM case of a packing that loads and unloads.

``calibrated_range_checks``: cost of the calibrated-range checks (``model/range_check.py``)
on 1e5 in-range contacts — the fast path's per-evaluation check (one max() against the
thresholds tabulated at build) against a ``ContactLaw.force`` evaluation, the exact
path's check of the solved state against ``contact()``, and the build-time thresholds
against the table setup.
"""

from __future__ import annotations

import math
import os
import time
import warnings

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402

from spherecontact.model import CalibrationRangeWarning, Material, Sphere, contact  # noqa: E402
from spherecontact.model.coefficients import default_coefficients  # noqa: E402
from spherecontact.model.fast import ContactLaw  # noqa: E402
from spherecontact.model.range_check import range_check  # noqa: E402
from spherecontact.model.unified import pair as unified_pair  # noqa: E402
from spherecontact.peers import jackson_green  # noqa: E402

# the steel–aluminium pair (yield ratio 4) lies outside the calibrated pair range (3): it is
# here for its cost, a realistic engineering pair, not its accuracy
warnings.filterwarnings("ignore", category=CalibrationRangeWarning)

N = 1_000_000
REPEAT = 5
R = 1e-3
STEEL = Material(E=210e9, nu=0.3, sigma_y=400e6, K=600e6, n=0.3)
ALU = Material(E=70e9, nu=0.33, sigma_y=100e6, K=200e6, n=0.5)


def _setups(pair, co) -> tuple[list[float], ContactLaw]:
    """``REPEAT`` timed ``ContactLaw`` setups of ``pair`` after one untimed (warm caches of the
    exact pair), and the last table."""
    ContactLaw(*pair, coeffs=co)
    setups = []
    for _ in range(REPEAT):
        t0 = time.perf_counter()
        law = ContactLaw(*pair, coeffs=co)
        setups.append(time.perf_counter() - t0)
    return setups, law


def _best(fun, repeat=REPEAT) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fun()
        times.append(time.perf_counter() - t0)
    return min(times)


def range_check_overhead(co, n: int = 100_000) -> dict:
    """Calibrated-range checks on n in-range contacts of an in-range dissimilar pair."""
    s1 = Sphere(R, STEEL)
    s2 = Sphere(2 * R, Material(E=110e9, nu=0.34, sigma_y=200e6, K=300e6, n=0.4))
    rng = np.random.default_rng(1)
    h = R * np.exp(rng.uniform(math.log(1e-6), math.log(0.3), n))
    with warnings.catch_warnings():
        warnings.simplefilter("error", CalibrationRangeWarning)  # the pair and h are in range
        law = ContactLaw(s1, s2, coeffs=co)
        t_force = _best(lambda: law.loading_force(h), 20)
        t_check = _best(lambda: law._table_causes(h), 20)
        t_setup = _best(lambda: ContactLaw(s1, s2, coeffs=co), 5)
        t_thresholds = _best(law._range_thresholds, 5)
        t_contact = _best(lambda: contact(s1, s2, h, co), 2)
        st = unified_pair(s1, s2, co).state_from_h(h)
        chk = range_check(s1, s2, co)
        t_state = _best(lambda: chk.check_state(st), 20)
    return {
        "contacts": n,
        "fast_force_s": t_force, "fast_check_s": t_check, "fast_fraction": t_check / t_force,
        "exact_contact_s": t_contact, "exact_check_s": t_state, "exact_fraction": t_state / t_contact,
        "setup_s": t_setup, "setup_thresholds_s": t_thresholds,
        "setup_fraction": t_thresholds / t_setup,
        "target_fraction": 0.05,
    }


def main() -> dict:
    rng = np.random.default_rng(0)
    h = R * np.exp(rng.uniform(math.log(1e-6), math.log(0.3), N))
    co = default_coefficients()
    equal = (Sphere(R, STEEL), Sphere(R, STEEL))
    dissimilar = (Sphere(R, STEEL), Sphere(2 * R, ALU))
    out: dict = {"contacts": N, "h_range_over_R": [1e-6, 0.3],
                 "coefficients_source": co.source, "repeat": REPEAT}

    t_eq = _best(lambda: contact(*equal, h, co), 2)
    t_dis = _best(lambda: contact(*dissimilar, h, co), 2)
    out["exact_equal_pair"] = {"seconds": t_eq, "contacts_per_s": N / t_eq}
    out["exact_dissimilar_pair"] = {"seconds": t_dis, "contacts_per_s": N / t_dis}

    laws = {}
    for name, pair in (("fast_equal_pair", equal), ("fast_dissimilar_pair", dissimilar)):
        setups, law = _setups(pair, co)
        laws[name] = law
        law.loading_force(h)
        t_fast = _best(lambda law=law: law.loading_force(h))
        out[name] = {
            "setup_s_median": float(np.median(setups)),
            "setup_s_max": float(np.max(setups)),
            "seconds": t_fast,
            "contacts_per_s": N / t_fast,
            "nodes": law.nodes,
            "error_bound": law.error,
        }

    law = laws["fast_dissimilar_pair"]
    h_up = h * rng.uniform(1.0, 1.3, N)
    half = np.where(rng.random(N) < 0.5, h, h_up)
    out["fast_with_history"] = {}
    for name, hm in (("all_loading", h), ("all_unloading", h_up), ("half_unloading", half)):
        law.force(h, hm)
        t = _best(lambda hm=hm: law.force(h, hm))
        out["fast_with_history"][name] = {"seconds": t, "contacts_per_s": N / t}

    # Jackson & Green (2005), steel hemisphere on a rigid flat: the same h array as ω
    Ep = STEEL.E_prime
    jackson_green(h, R, Ep, STEEL.sigma_y, STEEL.nu)
    t_jg = _best(lambda: jackson_green(h, R, Ep, STEEL.sigma_y, STEEL.nu))
    wall = ContactLaw(Sphere(R, STEEL), Sphere(math.inf, Material.rigid()), coeffs=co)
    wall.loading_force(h)
    t_wall = _best(lambda: wall.loading_force(h))
    out["jackson_green_2005_formula"] = {"seconds": t_jg, "contacts_per_s": N / t_jg}
    out["fast_rigid_flat"] = {"seconds": t_wall, "contacts_per_s": N / t_wall,
                              "setup_s": wall.setup_time}
    out["cost_relative_to_jackson_green"] = {
        "fast_rigid_flat": t_wall / t_jg,
        "fast_dissimilar_pair": out["fast_dissimilar_pair"]["seconds"] / t_jg,
        "exact_equal_pair": t_eq / t_jg,
        "exact_dissimilar_pair": t_dis / t_jg,
    }
    out["target"] = {"fast_contacts_per_s": 1e7, "setup_s": 0.05}
    out["setup_by_pair"] = setup_by_pair(co)
    out["calibrated_range_checks"] = range_check_overhead(co)
    return out


#: a copper alloy for the setup survey (Ludwik, SI units)
COPPER = Material(E=120e9, nu=0.34, sigma_y=70e6, K=300e6, n=0.4)
#: two perfectly plastic spheres of equal yield stress and E ratio 3 (E/σY 300 and 900, the
#: calibration pair two-pp-E300-nu0.3-vs-E900): the harder partner is decided by the modulus and
#: the interface terms are active, the slowest setup class measured
SOFT_EQUAL_YIELD = Material(E=300 * 100e6, nu=0.3, sigma_y=100e6)
STIFF_EQUAL_YIELD = Material(E=900 * 100e6, nu=0.3, sigma_y=100e6)


def setup_by_pair(co) -> dict:
    """Table setup (median of 5) and node count of the fast path for several pairs: the table
    resolution, hence the setup, depends on the pair (radius ratio; the interface terms of
    pairs whose fully plastic pressures come near each other)."""
    pairs = {"steel R / aluminium 2R": (Sphere(R, STEEL), Sphere(2 * R, ALU)),
             "steel R / aluminium R": (Sphere(R, STEEL), Sphere(R, ALU)),
             "steel 2R / aluminium R": (Sphere(2 * R, STEEL), Sphere(R, ALU)),
             "copper R / aluminium R": (Sphere(R, COPPER), Sphere(R, ALU)),
             "steel R / copper 2R": (Sphere(R, STEEL), Sphere(2 * R, COPPER)),
             "equal yield, E ratio 3, R / R": (Sphere(R, SOFT_EQUAL_YIELD), Sphere(R, STIFF_EQUAL_YIELD))}
    out = {}
    for name, pair in pairs.items():
        setups, law = _setups(pair, co)
        out[name] = {"setup_s_median": float(np.median(setups)), "nodes": law.nodes}
    return out


if __name__ == "__main__":
    import json

    print(json.dumps(main(), indent=2))
