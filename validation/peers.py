"""Published peer contact laws, written from their papers, vectorised over the approach.

Every function takes the approach (interference) as a float or array and returns
arrays shaped like it; approaches ≤ 0 give zero force and contact radius. Symbols
follow each paper; E' = E/(1 − ν²) (or the combined 1/E* = Σ(1 − ν_i²)/E_i),
R the sphere radius (or R* for two spheres). The model stage (DESIGN §5) is checked
against these laws; nothing here depends on ``spherecontact.model``.

Laws
----
* :func:`hertz` — Hertz (1882).
* :func:`jackson_green` — Jackson & Green (2005), J. Tribol. 127:343–354.
* :func:`kogut_etsion` — Kogut & Etsion (2002), J. Appl. Mech. 69:657–662.
* :func:`thornton` — Thornton (1997), J. Appl. Mech. 64:383–386.
* :func:`johnson_cavity_hardness` — Johnson (1970), J. Mech. Phys. Solids 18:115;
  Johnson (1985), Contact Mechanics, §6.3.
* :func:`biwa_storakers` — Biwa & Storåkers (1995), J. Mech. Phys. Solids 43:1303;
  c² fit of Storåkers, Biwa & Larsson (1997), Int. J. Solids Struct. 34:3061.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

__all__ = [
    "PeerCurve",
    "hertz",
    "jackson_green_critical",
    "jackson_green",
    "kogut_etsion_critical",
    "kogut_etsion",
    "thornton",
    "johnson_cavity_hardness",
    "biwa_storakers",
]


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
    """Hertz (1882): F = (4/3) E* √R* h^(3/2),  a² = R* h.

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
    omega_c = (math.pi * C * S_y / (2.0 * E_prime)) ** 2 * R
    P_c = 4.0 / 3.0 * (R / E_prime) ** 2 * (C * math.pi * S_y / 2.0) ** 3
    return omega_c, P_c, C


def jackson_green(omega, R: float, E_prime: float, S_y: float, nu: float) -> PeerCurve:
    """Jackson & Green (2005) FE fit: elastic–perfectly plastic hemisphere on a rigid flat.

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

    The published fits are not continuous at the switches (jumps of a few %).
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
    """
    d = np.maximum(_approach(delta), 0.0)
    E_star, R_star, p_y = (_positive("E_star", E_star), _positive("R_star", R_star),
                           _positive("p_y", p_y))
    d_y = (math.pi * p_y / (2.0 * E_star)) ** 2 * R_star
    F_y = 4.0 / 3.0 * E_star * math.sqrt(R_star) * d_y**1.5
    F = np.where(d <= d_y, 4.0 / 3.0 * E_star * math.sqrt(R_star) * d**1.5,
                 F_y + math.pi * p_y * R_star * (d - d_y))
    return PeerCurve(F, np.sqrt(R_star * d))


# --------------------------------------------------------------------- Johnson cavity model
def johnson_cavity_hardness(a_over_R, E: float, nu: float, Y: float) -> np.ndarray:
    """Johnson's expanding-cavity model: mean pressure under a blunt indenter, p_m/Y.

    p_m/Y = (2/3) [1 + ln( (E tanβ/Y + 4(1 − 2ν)) / (6(1 − ν)) )],  tanβ ≈ a/R for a
    sphere (Johnson 1970; Johnson 1985 §6.3). For ν = 1/2 this is the familiar
    p_m/Y = (2/3)[1 + ln(E a/(3 Y R))]. Valid in the elastic–plastic range (Level II).
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
    """
    hh = np.maximum(_approach(h), 0.0)
    R_star, sigma_0 = _positive("R_star", R_star), _positive("sigma_0", sigma_0)
    if not (math.isfinite(n) and n >= 0.0):
        raise ValueError(f"n must be a finite number >= 0, got {n!r}")
    c2 = 1.43 * math.exp(-0.97 * n)
    a = np.sqrt(2.0 * c2 * R_star * hh)
    p_m = 3.07 * sigma_0 * (0.32 * a / R_star) ** n
    return PeerCurve(math.pi * a * a * p_m, a)
