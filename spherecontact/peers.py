"""Published peer contact laws, written from their papers, vectorised over the approach.

Every function takes the approach (interference) as a float or array and returns
arrays shaped like it; approaches ≤ 0 give zero force and contact radius. Symbols
follow each paper; E' = E/(1 − ν²) (or the combined 1/E* = Σ(1 − ν_i²)/E_i),
R the sphere radius (or R* for two spheres). The model stage (docs/design.md §5) is checked
against these laws; nothing here depends on ``spherecontact.model``.

Every law carries its stated range of validity as data next to it (``*_RANGE``, in the
law's own variable) and :func:`in_range` turns it into a mask; ``tests/test_peers.py``
reproduces, for each law, a number printed in its source or (where no printed value
could be reached) an identity its published equations must satisfy — each test says which.

Laws, sources and ranges
------------------------
* :func:`hertz` — Hertz (1882); Johnson (1985), *Contact Mechanics*, §4.2 (a³ = 3PR/(4E*),
  δ = a²/R). Range: elastic, ω ≤ ω_c (first yield; :data:`HERTZ_RANGE`).
* :func:`jackson_green` — Jackson & Green (2005), J. Tribol. 127:343–354 (C(ν), ω_c, P_c and the
  fits for P/P_c, A, H_G). The primary text was not reachable here: the equations agree
  term by term with their transcription in an independent implementation of the paper's
  fits; equation numbers are therefore not quoted. Range: 0 ≤ ω* ≤ 110 (:data:`JACKSON_GREEN_RANGE`).
* :func:`kogut_etsion` — Kogut & Etsion (2002), J. Appl. Mech. 69:657–662 (piecewise fits of
  P/P_c, A/A_c and p/Y for 1 ≤ ω* ≤ 6 and 6 ≤ ω* ≤ 110, ω_c after Chang, Etsion & Bogy 1987);
  the dimensional form (1.37, 1.87 E k^… R^… ω^…) as printed by Kogut & Etsion (2003),
  Tribol. Trans. 46:383. Range: 0 ≤ ω* ≤ 110, fully plastic beyond (:data:`KOGUT_ETSION_RANGE`).
* :func:`thornton`, :func:`thornton_unloading` — Thornton (1997), J. Appl. Mech. 64:383–386:
  Hertz truncated at the limiting contact pressure p_y on loading, Hertz with the
  plastically flattened radius R_p on unloading, and the closed-form restitution coefficient
  they give. Range: elastic–perfectly plastic, up to the onset of a fully plastic contact,
  taken as Kogut–Etsion's ω* ≤ 110 (:data:`THORNTON_RANGE`).
* :func:`johnson_cavity_hardness` — Johnson (1970), J. Mech. Phys. Solids 18:115; Johnson
  (1985) §6.3 (expanding cavity model, cone of semi-angle tanβ ≈ a/R for a sphere).
  Range: Johnson's elastic–plastic regime 3 ≤ E'a/(Yρ) ≤ 40 (:data:`CAVITY_RANGE`).
* :func:`biwa_storakers` — Biwa & Storåkers (1995), J. Mech. Phys. Solids 43:1303; c² fit of
  Storåkers, Biwa & Larsson (1997), Int. J. Solids Struct. 34:3061. Neither text was
  reachable here; the coefficients are those this module has carried since it was
  written, and the test checks the law's similarity identities and the exact linear case
  c² = 1/2 of the similarity solution (Hill, Storåkers & Zdunek 1989). Range: a rigid–plastic
  law, i.e. the fully plastic regime E'a/(σ_Y ρ) ≥ 40 (Johnson 1985 §6.3;
  :data:`BIWA_STORAKERS_RANGE`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

__all__ = [
    "PeerCurve",
    "HERTZ_RANGE",
    "JACKSON_GREEN_RANGE",
    "KOGUT_ETSION_RANGE",
    "THORNTON_RANGE",
    "CAVITY_RANGE",
    "BIWA_STORAKERS_RANGE",
    "in_range",
    "thornton_unloading",
    "thornton_restitution",
    "hertz",
    "first_yield_approach",
    "jackson_green_critical",
    "jackson_green",
    "kogut_etsion_critical",
    "kogut_etsion",
    "thornton",
    "johnson_cavity_hardness",
    "biwa_storakers",
]


#: ω/ω_c where Hertz holds: elastic, up to first yield
HERTZ_RANGE = (0.0, 1.0)
#: ω* = ω/ω_c covered by Jackson & Green's (2005) fits
JACKSON_GREEN_RANGE = (0.0, 110.0)
#: ω* = ω/ω_c of Kogut & Etsion's (2002) fits (Hertz below 1; fully plastic beyond 110)
KOGUT_ETSION_RANGE = (0.0, 110.0)
#: δ/δ_c (δ_c the first-yield approach) where Thornton's (1997) truncated Hertz pressure is
#: meant to hold: elastic–plastic, up to a fully plastic contact (Kogut–Etsion's 110)
THORNTON_RANGE = (0.0, 110.0)
#: E'a/(Yρ) of Johnson's (1985 §6.3) elastic–plastic regime (first yield to fully plastic)
CAVITY_RANGE = (3.0, 40.0)
#: E'a/(σ_Y ρ) of a fully plastic contact (Johnson 1985 §6.3), where a rigid–plastic law holds
BIWA_STORAKERS_RANGE = (40.0, math.inf)


def in_range(x, bounds: tuple[float, float]) -> np.ndarray:
    """Mask of the values of a law's own variable ``x`` inside its stated range ``bounds``
    (both ends included)."""
    x = np.asarray(x, dtype=float)
    lo, hi = bounds
    return (x >= lo) & (x <= hi)


class PeerCurve(NamedTuple):
    """Force F and contact radius a at the given approaches (arrays)."""

    F: np.ndarray
    a: np.ndarray


def _approach(x) -> np.ndarray:
    x = np.asarray(x, dtype=float)
    if not np.all(np.isfinite(x)):
        raise ValueError("approach must be finite (no NaN or inf)")
    return x


def _positive(name: str, value: float) -> float:
    v = float(value)
    if not (math.isfinite(v) and v > 0.0):
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    return v


def hertz(h, E_star: float, R_star: float) -> PeerCurve:
    """Hertz (1882): F = (4/3) E* √R* h^(3/2),  a² = R* h  (Johnson 1985 §4.2: a³ = 3PR/(4E*),
    δ = a²/R). Holds in the elastic range, h ≤ ω_c (:data:`HERTZ_RANGE`).

    Parameters
    ----------
    h : mutual approach (≤ 0: no contact).
    E_star : contact modulus, 1/E* = (1 − ν_1²)/E_1 + (1 − ν_2²)/E_2.
    R_star : relative radius, 1/R* = 1/R_1 + 1/R_2.
    """
    h = np.maximum(_approach(h), 0.0)
    E_star, R_star = _positive("E_star", E_star), _positive("R_star", R_star)
    return PeerCurve(4.0 / 3.0 * E_star * math.sqrt(R_star) * h**1.5, np.sqrt(R_star * h))


# --------------------------------------------------------------------- Jackson & Green (2005)
def first_yield_approach(R: float, E_prime: float, S_y: float, nu: float) -> float:
    """Approach of first yield of Jackson & Green (2005), ω_c = R (π C S_y/(2E'))²,
    C = 1.295 exp(0.736 ν) (ν of the deforming body; no check of the inputs: the FE solver
    calls it per step set-up, :func:`jackson_green_critical` checks them)."""
    return R * (math.pi * 1.295 * math.exp(0.736 * nu) * S_y / (2.0 * E_prime)) ** 2


def jackson_green_critical(R: float, E_prime: float, S_y: float, nu: float):
    """Critical interference, load and yield-strength factor of Jackson & Green (2005).

    C = 1.295 exp(0.736 ν),  ω_c = (π C S_y/(2E'))² R,  P_c = (4/3)(R/E')² (C π S_y/2)³
    (their eqs. for the onset of yield, ν of the deforming hemisphere).

    Returns
    -------
    (omega_c, P_c, C)
    """
    R, E_prime, S_y = _positive("R", R), _positive("E_prime", E_prime), _positive("S_y", S_y)
    C = 1.295 * math.exp(0.736 * nu)
    omega_c = first_yield_approach(R, E_prime, S_y, nu)
    P_c = 4.0 / 3.0 * (R / E_prime) ** 2 * (C * math.pi * S_y / 2.0) ** 3
    return omega_c, P_c, C


def jackson_green(omega, R: float, E_prime: float, S_y: float, nu: float) -> PeerCurve:
    """Jackson & Green (2005) FE fit: elastic–perfectly plastic hemisphere on a rigid flat.

    Holds for 0 ≤ ω* ≤ 110 (:data:`JACKSON_GREEN_RANGE`).

    With ω* = ω/ω_c (see :func:`jackson_green_critical`), e_y = S_y/E':

    * 0 ≤ ω* < 1.9 (Hertz):  P = P_c ω*^(3/2),  A = π R ω.
    * ω* ≥ 1.9:
      P/P_c = exp(−¼ ω*^(5/12)) ω*^(3/2) + (4 H_G/(C S_y)) [1 − exp(−(1/25) ω*^(5/9))] ω*,
      A = π R ω (ω*/1.9)^B,  B = 0.14 exp(23 e_y),
      H_G/S_y = 2.84 [1 − exp(−0.82 (a/R)^(−0.7))]  (a from A = π a²).

    Returns F = P and a = √(A/π).
    """
    w = np.maximum(_approach(omega), 0.0)
    omega_c, P_c, C = jackson_green_critical(R, E_prime, S_y, nu)
    ws = w / omega_c
    B = 0.14 * math.exp(23.0 * S_y / E_prime)
    plastic = ws >= 1.9
    a = np.sqrt(R * w * np.where(plastic, (ws / 1.9) ** B, 1.0))
    with np.errstate(divide="ignore"):
        H_G = S_y * 2.84 * (1.0 - np.exp(-0.82 * np.where(plastic, a / R, 1.0) ** -0.7))
    P_pl = P_c * (
        np.exp(-0.25 * ws ** (5.0 / 12.0)) * ws**1.5
        + 4.0 * H_G / (C * S_y) * (1.0 - np.exp(-ws ** (5.0 / 9.0) / 25.0)) * ws
    )
    return PeerCurve(np.where(plastic, P_pl, P_c * ws**1.5), a)


# --------------------------------------------------------------------- Kogut & Etsion (2002)
def kogut_etsion_critical(R: float, E_prime: float, Y: float, nu: float):
    """Critical interference of Kogut & Etsion (2002) (after Chang, Etsion & Bogy 1987).

    K = 0.454 + 0.41 ν,  H = 2.8 Y,  ω_c = (π K H/(2E))² R,
    P_c = (2/3) K H π R ω_c,  A_c = π R ω_c.

    Returns
    -------
    (omega_c, P_c, A_c, K)
    """
    R, E_prime, Y = _positive("R", R), _positive("E_prime", E_prime), _positive("Y", Y)
    K = 0.454 + 0.41 * nu
    H = 2.8 * Y
    omega_c = (math.pi * K * H / (2.0 * E_prime)) ** 2 * R
    return omega_c, 2.0 / 3.0 * K * H * math.pi * R * omega_c, math.pi * R * omega_c, K


def kogut_etsion(omega, R: float, E_prime: float, Y: float, nu: float) -> PeerCurve:
    """Kogut & Etsion (2002) FE fit: elastic–perfectly plastic sphere pressed by a rigid flat.

    With ω* = ω/ω_c (see :func:`kogut_etsion_critical`):

    | ω*         | P/P_c             | A/A_c             |
    |------------|-------------------|-------------------|
    | < 1        | ω*^1.5 (Hertz)    | ω*                |
    | 1 – 6      | 1.03 ω*^1.425     | 0.93 ω*^1.136     |
    | 6 – 110    | 1.40 ω*^1.263     | 0.94 ω*^1.146     |
    | ≥ 110      | (3/K) ω*  (P = H A) | 2 ω*  (fully plastic, A = 2πRω) |

    The published fits are not continuous at the switches (jumps of a few %). Their stated
    range is ω* ≤ 110 (:data:`KOGUT_ETSION_RANGE`); beyond it the contact is fully plastic
    and the last row is Kogut & Etsion's fully plastic limit, not a fit.
    """
    w = np.maximum(_approach(omega), 0.0)
    omega_c, P_c, A_c, K = kogut_etsion_critical(R, E_prime, Y, nu)
    ws = w / omega_c
    P = np.select(
        [ws < 1.0, ws < 6.0, ws < 110.0],
        [ws**1.5, 1.03 * ws**1.425, 1.40 * ws**1.263],
        3.0 / K * ws,
    )
    A = np.select(
        [ws < 1.0, ws < 6.0, ws < 110.0],
        [ws, 0.93 * ws**1.136, 0.94 * ws**1.146],
        2.0 * ws,
    )
    return PeerCurve(P_c * P, np.sqrt(A_c * A / math.pi))


# --------------------------------------------------------------------- Thornton (1997)
def thornton(delta, E_star: float, R_star: float, p_y: float) -> PeerCurve:
    """Thornton (1997): Hertzian pressure truncated at the limiting contact pressure p_y.

    δ_y = (π p_y/(2E*))² R*,  F_y = (4/3) E* √R* δ_y^(3/2);
    F = Hertz for δ ≤ δ_y,  F = F_y + π p_y R* (δ − δ_y) beyond;  a² = R* δ throughout.
    (dF/dδ is continuous at δ_y: 2E*a_y = π p_y R*.) Thornton sets p_y from the onset of
    yield; Johnson (1985, §6.2) gives a peak Hertz pressure of 1.60 Y at first yield (ν = 0.3).
    Meant for elastic–perfectly plastic spheres up to a fully plastic contact
    (δ/δ_y ≤ 110, :data:`THORNTON_RANGE`).
    """
    d = np.maximum(_approach(delta), 0.0)
    E_star, R_star, p_y = (_positive("E_star", E_star), _positive("R_star", R_star),
                           _positive("p_y", p_y))
    d_y = (math.pi * p_y / (2.0 * E_star)) ** 2 * R_star
    F_y = 4.0 / 3.0 * E_star * math.sqrt(R_star) * d_y**1.5
    F = np.where(d <= d_y, 4.0 / 3.0 * E_star * math.sqrt(R_star) * d**1.5,
                 F_y + math.pi * p_y * R_star * (d - d_y))
    return PeerCurve(F, np.sqrt(R_star * d))


def thornton_unloading(delta, delta_max: float, E_star: float, R_star: float,
                       p_y: float) -> tuple[np.ndarray, float]:
    """Thornton (1997) unloading from the peak of :func:`thornton`: Hertz with the flattened radius.

    R_p = 4E* a*³/(3F*),  δ_p = δ* − 3F*/(4E* a*),  F = (4/3) E* √R_p (δ − δ_p)^(3/2)
    (F* and a* = √(R* δ*) the loading's peak; below yield R_p = R*, δ_p = 0).

    Returns
    -------
    (F at ``delta`` on the unloading branch, δ_p)
    """
    d = _approach(delta)
    E_star, R_star = _positive("E_star", E_star), _positive("R_star", R_star)
    d_max = _positive("delta_max", delta_max)
    F_max = float(thornton(d_max, E_star, R_star, p_y).F)
    a_max = math.sqrt(R_star * d_max)
    R_p = 4.0 * E_star * a_max**3 / (3.0 * F_max)
    d_p = d_max - 3.0 * F_max / (4.0 * E_star * a_max)
    return 4.0 / 3.0 * E_star * math.sqrt(R_p) * np.maximum(d - d_p, 0.0) ** 1.5, d_p


def thornton_restitution(v_ratio) -> np.ndarray:
    """Thornton's (1997) closed-form restitution coefficient of elastic–perfectly plastic spheres.

    e = (6√3/5)^½ [1 − (1/6) x²]^½ [x/(x + 2√(6/5 − x²/5))]^¼,  x = V_y/V_i ≤ 1,
    which tends to 1.185 x^¼ for V_i ≫ V_y (both as printed by Thornton).
    """
    x = np.asarray(v_ratio, dtype=float)
    return (math.sqrt(6.0 * math.sqrt(3.0) / 5.0) * np.sqrt(1.0 - x * x / 6.0)
            * (x / (x + 2.0 * np.sqrt(6.0 / 5.0 - x * x / 5.0))) ** 0.25)


# --------------------------------------------------------------------- Johnson cavity model
def johnson_cavity_hardness(a_over_R, E: float, nu: float, Y: float) -> np.ndarray:
    """Johnson's expanding-cavity model: mean pressure under a blunt indenter, p_m/Y.

    p_m/Y = (2/3) [1 + ln( (E tanβ/Y + 4(1 − 2ν)) / (6(1 − ν)) )],  tanβ ≈ a/R for a
    sphere (Johnson 1970; Johnson 1985 §6.3). For ν = 1/2 this is the form Johnson prints,
    p_m/Y = (2/3)[1 + ln(E a/(3 Y R))]. Valid in Johnson's elastic–plastic range
    3 ≤ E'a/(Yρ) ≤ 40 (:data:`CAVITY_RANGE`).
    """
    x = np.asarray(a_over_R, dtype=float)
    E, Y = _positive("E", E), _positive("Y", Y)
    arg = (E * x / Y + 4.0 * (1.0 - 2.0 * nu)) / (6.0 * (1.0 - nu))
    with np.errstate(divide="ignore", invalid="ignore"):
        return 2.0 / 3.0 * (1.0 + np.log(arg))


# --------------------------------------------------------------------- Biwa & Storåkers (1995)
def biwa_storakers(h, R_star: float, sigma_0: float, n: float) -> PeerCurve:
    """Rigid–plastic power-law similarity law (Biwa & Storåkers 1995; Storåkers et al. 1997).

    Flow curve σ = σ_0 ε^n (n = 1/m). Self-similar indentation:
    a² = 2 c² R* h with c² = 1.43 exp(−0.97 n)  (Storåkers, Biwa & Larsson 1997),
    p_m = 3.07 σ_0 (0.32 a/R*)^n                (Biwa & Storåkers 1995),  F = π a² p_m.

    A rigid–plastic law: it holds in the fully plastic regime, E'a/(σ_Y ρ) ≥ 40
    (:data:`BIWA_STORAKERS_RANGE`).
    """
    hh = np.maximum(_approach(h), 0.0)
    R_star, sigma_0 = _positive("R_star", R_star), _positive("sigma_0", sigma_0)
    if not (math.isfinite(n) and n >= 0.0):
        raise ValueError(f"n must be a finite number >= 0, got {n!r}")
    c2 = 1.43 * math.exp(-0.97 * n)
    a = np.sqrt(2.0 * c2 * R_star * hh)
    p_m = 3.07 * sigma_0 * (0.32 * a / R_star) ** n
    return PeerCurve(math.pi * a * a * p_m, a)
