"""Contact table v2 (``spherecontact-contact-table/2``): the law of a material pair for DEM codes.

One text file holds the fast path (:class:`~spherecontact.model.fast.ContactLaw`) of one material
pair at one or several radius ratios ρ = R_2/R_1 ("slices"), with everything a particle code needs
to evaluate F, dF/dh, a and h_1 for any (h, h_max) and any radii in the file's ratio range,
without this package: ``dem/FORMAT.md`` is the specification, ``dem/spherecontact_table.c`` a C99
evaluator, :class:`TableLaw` the NumPy one (the reference the C code and the ratio interpolation
are measured against).

* One slice: the law is ``ContactLaw(s1, s2, h_max, beyond="table").force(h, h_max)`` and its full
  state, for the radii of the slice and, by the size scaling F(λh; λR_1, λR_2) = λ²F(h; R_1, R_2),
  a(λh; …) = λa, for every pair of radii with the same ratio.
* Several slices (``ratios``): each is evaluated at the contact's size (λ_i = R*/R*_i) and the
  results are interpolated in ln ρ (Lagrange through the nearest ``min(4, slices)`` slices); the
  error of that interpolation against the exact model is measured when the file is written
  (:func:`ratio_interpolation_error`) and stored in the file.

Default range of every slice: the calibrated range of the model (``ContactLaw.h_calibrated``,
:func:`calibrated_law`); beyond it the table's explicit rule (``dem/FORMAT.md``).
"""

from __future__ import annotations

import json
import math
import warnings
from pathlib import Path

import numpy as np

from .fast import ContactLaw, _hermite
from .sphere import Sphere

__all__ = ["FORMAT", "SUFFIX", "calibrated_law", "write_table2", "read_table2", "TableLaw",
           "ratio_interpolation_error", "NODE_COLUMNS"]

#: format name and version, the first line of the file
FORMAT = "spherecontact-contact-table/2"
#: file name suffix of a v2 table
SUFFIX = ".sct"
#: the columns of a node row, in order
NODE_COLUMNS = ("ln_h", "ln_F", "dln_F_left", "dln_F_right", "ln_a", "dln_a_left", "dln_a_right",
                "phi", "dphi_left", "dphi_right", "recovery", "m", "h1_res")
#: a contact's ln(R_2/R_1) may lie this far outside the file's ratio range (then it is clamped)
RATIO_TOLERANCE = 1e-6
#: slices of the Lagrange stencil in ln ρ
ORDER = 4
#: normalised extent of a ratio-range table's slices over the largest calibrated h/R* of its slices
EXTENT_MARGIN = 1.25
#: default spacing of slices, R2/R1 of neighbouring slices
SLICE_STEP = 2.0 ** 0.25
#: reference evaluations per slice stored in the file (``check`` lines)
CHECKS = 12


def strict_json(v):
    """``v`` with every non-finite float as the string "inf", "-inf" or "nan" (a flat's radius,
    a rigid body's modulus): standard JSON, which a C or C++ reader parses."""
    if isinstance(v, dict):
        return {k: strict_json(x) for k, x in v.items()}
    if isinstance(v, list | tuple):
        return [strict_json(x) for x in v]
    if isinstance(v, float) and not math.isfinite(v):
        return str(v)
    return v


def _r_star(R1, R2):
    """Effective radius R* = R_1 R_2/(R_1 + R_2) (R_1 for a flat partner, R_2 = ∞)."""
    R1, R2 = np.asarray(R1, dtype=float), np.asarray(R2, dtype=float)
    with np.errstate(invalid="ignore"):
        return np.where(np.isinf(R2), R1, R1 * R2 / (R1 + R2))


def calibrated_law(s1: Sphere, s2: Sphere, h_max: float | None = None, coeffs=None) -> ContactLaw:
    """The pair's :class:`ContactLaw` with the table rule beyond its ends (``beyond="table"``) up to
    ``h_max``; by default up to the model's calibrated range, ``ContactLaw.h_calibrated`` (the
    largest approach at which h/R, a/R, Λ and the flow-table slope are all inside it), capped by
    the model's domain, or ContactLaw's own default where no approach check is ever reached.

    Parameters
    ----------
    s1, s2 : the spheres (body 1, body 2).
    h_max : largest tabulated approach (None: the calibrated range).
    coeffs : coefficient set (None: the calibrated set shipped with the package).
    """
    law = ContactLaw(s1, s2, h_max=h_max, coeffs=coeffs, beyond="table")
    if h_max is not None:
        return law
    hc = law.h_calibrated
    if not (math.isfinite(hc) and hc > 1e3 * law.h_min):
        return law
    h = min(hc, law.pair.domain.h_max)
    if h == law.h_max:
        return law
    return ContactLaw(s1, s2, h_max=h, coeffs=coeffs, beyond="table")


def _fmt(v: float) -> str:
    return "inf" if v == math.inf else f"{float(v):.17g}"


def _slice_lines(i: int, ratio: float, law: ContactLaw) -> list[str]:
    tab = law.tables()
    s1, s2 = law.pair.s1, law.pair.s2
    head = (f"slice {i} ratio {_fmt(ratio)} R1 {_fmt(s1.radius)} R2 {_fmt(s2.radius)} "
            f"nodes {tab['ln_h'].size} h_elastic {_fmt(tab['h_elastic'])} h_min {_fmt(tab['h_min'])} "
            f"h_max {_fmt(tab['h_max'])}")
    cols = np.column_stack([tab[k] for k in NODE_COLUMNS])
    return [head] + [" ".join(_fmt(v) for v in row) for row in cols]


def _ratio(s1: Sphere, s2: Sphere) -> float:
    return math.inf if math.isinf(s2.radius) else s2.radius / s1.radius


def write_table2(path, s1: Sphere, s2: Sphere, ratios=None, h_max: float | None = None,
                 coeffs=None, laws: list[ContactLaw] | None = None, probes: int = 3) -> dict:
    """Write the pair's v2 table (``dem/FORMAT.md``) to ``path`` (``.sct``) and return its meta.

    Parameters
    ----------
    path : output file, ending in ``.sct``.
    s1, s2 : the spheres; body 1's radius is the reference radius of every slice.
    ratios : radius ratios R_2/R_1 of the slices, increasing (None: the one ratio of s1, s2;
        a flat, R_2 = ∞, is a one-slice table).
    h_max : largest tabulated approach of every slice (None: each slice's calibrated range).
    coeffs : coefficient set (None: the calibrated set shipped with the package).
    laws : the slices' laws, already built (``beyond="table"``; then ``ratios``, ``h_max`` and
        ``coeffs`` are taken from them).
    probes : ratios probed per interval between slices for the measured interpolation error.

    Returns
    -------
    dict : the file's meta (JSON object of its ``meta`` line).
    """

    if Path(path).suffix != SUFFIX:
        raise ValueError(f"path must end in {SUFFIX}, got {str(path)!r}")
    if laws is None:
        if ratios is None:
            ratios = [_ratio(s1, s2)]
        ratios = [float(r) for r in ratios]
        if any(not (r > 0.0) for r in ratios) or any(b <= a for a, b in zip(ratios, ratios[1:],
                                                                            strict=False)):
            raise ValueError(f"ratios must be > 0 and increasing, got {ratios!r}")
        if len(ratios) > 1 and math.isinf(ratios[-1]):
            raise ValueError("a flat partner (ratio inf) is a table of its own: give ratios=[inf]")
        bodies = [Sphere(math.inf if math.isinf(r) else r * s1.radius, s2.material) for r in ratios]
        laws = [calibrated_law(s1, b, h_max, coeffs) for b in bodies]
        if h_max is None and len(laws) > 1:
            # one normalised extent for all slices, EXTENT_MARGIN times the largest calibrated
            # h/R* among them: a contact between slices is then inside the tables up to its own
            # calibrated range, which can exceed its neighbours' (h/R of the body that reaches the
            # limit first switches between them; each slice's own range is in the meta)
            top = EXTENT_MARGIN * max(law.h_max / law.pair.R_star for law in laws)
            laws = [law if top * law.pair.R_star <= law.h_max else
                    ContactLaw(s1, b, h_max=min(top * law.pair.R_star, law.pair.domain.h_max),
                               coeffs=coeffs, beyond="table")
                    for law, b in zip(laws, bodies, strict=True)]
    for law in laws:
        if law.beyond != "table":
            raise ValueError("laws must be built with beyond='table' (the file's rule beyond its ends)")
    ratios = [_ratio(law.pair.s1, law.pair.s2) for law in laws]
    law0 = laws[0]
    meta = {"format": FORMAT,
            "body1": {"radius": s1.radius, **s1.material.describe()},
            "body2": {"radius": s2.radius, **s2.material.describe()},
            "coefficients_source": law0.pair.coeffs.source,
            "units": "consistent units of the inputs: lengths as the radii, forces as E·R²",
            "ratio_range": [ratios[0], ratios[-1]],
            "ratio_interpolation": f"Lagrange in ln(R2/R1) through the nearest min({ORDER}, slices)",
            "ratio_tolerance": RATIO_TOLERANCE,
            "slices": [{"ratio": r, "R1": law.pair.s1.radius, "R2": law.pair.s2.radius,
                        "h_max": law.h_max, "h_calibrated": law.h_calibrated, "nodes": law.nodes,
                        "error_bound": dict(law.error),
                        "calibrated_range_warnings": list(law.range_issues.values())}
                       for r, law in zip(ratios, laws, strict=True)]}
    lines = [f"slices {len(laws)}"]
    for i, (r, law) in enumerate(zip(ratios, laws, strict=True)):
        lines += _slice_lines(i, r, law)
    body = "\n".join([FORMAT, *lines]) + "\n"
    if len(laws) > 1:
        meta["ratio_interpolation_error"] = ratio_interpolation_error(body, laws, probes)
    # reference evaluations of the file's own rule (an implementation reproduces them): per slice,
    # loading points from 1e-4 to 1.5 times its h_max and as many just below each peak
    tl = TableLaw.from_text(body)
    checks = []
    for law, r in zip(laws, ratios, strict=True):
        R1 = law.pair.s1.radius
        R2 = math.inf if math.isinf(r) else r * R1
        hm = np.geomspace(law.h_max * 1e-4, law.h_max * 1.5, CHECKS // 2)
        h, hmax = np.concatenate([hm, hm * 0.995]), np.concatenate([hm, hm])
        F, k, a, h1 = tl.evaluate(h, hmax, R1, R2)
        checks += ["check " + " ".join(_fmt(v) for v in row)
                   for row in zip(np.full(h.size, R1), np.full(h.size, R2), h, hmax, F, k, a, h1,
                                  strict=True)]
    meta = strict_json(meta)
    text = "\n".join([FORMAT, "# contact law of a material pair for DEM codes; specification: "
                       "dem/FORMAT.md", f"meta {json.dumps(meta, allow_nan=False)}", *lines,
                       *checks, "end"]) + "\n"
    Path(path).write_text(text, encoding="utf-8")
    return meta


def read_table2(path_or_text) -> dict:
    """Parse a v2 table (a path, or the text itself) into plain arrays.

    Returns
    -------
    dict with ``meta`` (dict or None), ``slices`` (list of dicts: ``ratio``, ``R1``, ``R2``,
    ``h_elastic``, ``h_min``, ``h_max`` and the arrays of :data:`NODE_COLUMNS`) and ``checks``
    (array of rows R1 R2 h h_max F dF/dh a h1).

    Raises
    ------
    ValueError naming the line and what is wrong with it.
    """
    text = path_or_text if "\n" in str(path_or_text) else Path(path_or_text).read_text(encoding="utf-8")
    lines = text.splitlines()
    if not lines or lines[0].strip() != FORMAT:
        raise ValueError(f"not a {FORMAT} file: first line {lines[0][:60] if lines else ''!r}")
    out = {"meta": None, "slices": [], "checks": []}
    i, nslices = 1, None
    while i < len(lines):
        words = lines[i].split()
        i += 1
        if not words or words[0].startswith("#"):
            continue
        key = words[0]
        if key == "meta":
            out["meta"] = json.loads(lines[i - 1][5:])
        elif key == "slices":
            nslices = int(words[1])
        elif key == "slice":
            try:
                kv = dict(zip(words[2::2], words[3::2], strict=True))
                n = int(kv["nodes"])
                sl = {k: float(kv[k]) for k in ("ratio", "R1", "R2", "h_elastic", "h_min", "h_max")}
                rows = [[float(v) for v in lines[i + j].split()] for j in range(n)]
                if n < 2 or any(len(r) != len(NODE_COLUMNS) for r in rows):
                    raise ValueError
            except (ValueError, KeyError, IndexError):
                raise ValueError(f"slice {words[1] if len(words) > 1 else '?'} (line {i}): expected "
                                 "'slice I ratio R R1 R R2 R nodes N h_elastic H h_min H h_max H' and "
                                 f"N >= 2 rows of {len(NODE_COLUMNS)} numbers") from None
            rows = np.array(rows)
            i += n
            sl.update({c: rows[:, j].copy() for j, c in enumerate(NODE_COLUMNS)})
            out["slices"].append(sl)
        elif key == "check":
            out["checks"].append([float(v) for v in words[1:]])
        elif key == "end":
            break
        else:
            raise ValueError(f"line {i}: unknown keyword {key!r}")
    if nslices is None or nslices != len(out["slices"]) or nslices < 1:
        raise ValueError(f"'slices {nslices}' does not match the {len(out['slices'])} slices read")
    out["checks"] = np.array(out["checks"]).reshape(-1, 8)
    return out


def _hermite_coeffs(y, d_left, d_right, s):
    """c0..c3 per interval from node values y and one-sided slopes (``fast._hermite``, so the
    doubles are the table's own)."""
    return _hermite(y[:-1], y[1:], d_right[:-1], d_left[1:], np.diff(s))


class _Slice:
    """One slice of a v2 table, evaluated at normalised approaches q (the file's rule)."""

    def __init__(self, sl: dict) -> None:
        self.ratio, self.R1, self.R2 = sl["ratio"], sl["R1"], sl["R2"]
        self.Rs = float(_r_star(self.R1, self.R2))
        self.h_elastic, self.h_min, self.h_max = sl["h_elastic"], sl["h_min"], sl["h_max"]
        s = sl["ln_h"]
        self.s, self.inv = s, 1.0 / np.diff(s)
        self.cF = _hermite_coeffs(sl["ln_F"], sl["dln_F_left"], sl["dln_F_right"], s)
        self.ca = _hermite_coeffs(sl["ln_a"], sl["dln_a_left"], sl["dln_a_right"], s)
        self.cp = _hermite_coeffs(sl["phi"], sl["dphi_left"], sl["dphi_right"], s)
        self.sl = sl

    def at(self, q):
        """ln F, d ln F/d ln h, ln a, φ, recovery, m, h1_res at approaches q > 0."""
        sl, s = self.sl, np.log(q)
        n = self.s.size
        j = np.clip(np.searchsorted(self.s, s, side="right") - 1, 0, n - 2)
        t = (s - self.s[j]) * self.inv[j]
        c = self.cF[j]
        y = ((c[:, 3] * t + c[:, 2]) * t + c[:, 1]) * t + c[:, 0]
        g = ((c[:, 3] * (3.0 * t) + 2.0 * c[:, 2]) * t + c[:, 1]) * self.inv[j]
        c = self.ca[j]
        ya = c[:, 0] + t * (c[:, 1] + t * (c[:, 2] + t * c[:, 3]))
        c = self.cp[j]
        phi = c[:, 0] + t * (c[:, 1] + t * (c[:, 2] + t * c[:, 3]))
        un = [sl[k][j] + t * (sl[k][j + 1] - sl[k][j]) for k in ("recovery", "m", "h1_res")]
        out = [y, g, ya, phi, *un]
        # the explicit rule beyond the ends: ln F, ln a linear in ln h with the end node's one-sided
        # slope, φ and the unloading parameters of the end node
        for mask, e, side in ((q < self.h_min, 0, "right"), (q > self.h_max, -1, "left")):
            if mask.any():
                ds = s[mask] - self.s[e]
                out[0][mask] = sl["ln_F"][e] + sl[f"dln_F_{side}"][e] * ds
                out[1][mask] = sl[f"dln_F_{side}"][e]
                out[2][mask] = sl["ln_a"][e] + sl[f"dln_a_{side}"][e] * ds
                for o, k in zip(out[3:], ("phi", "recovery", "m", "h1_res"), strict=True):
                    o[mask] = sl[k][e]
        return out


class TableLaw:
    """NumPy evaluator of a v2 table file (the rule of ``dem/FORMAT.md``).

    Parameters
    ----------
    table : the parsed file (:func:`read_table2`).
    """

    def __init__(self, table: dict) -> None:
        self.meta = table["meta"]
        self.slices = [_Slice(sl) for sl in table["slices"]]
        self.x = np.log([sl.ratio for sl in self.slices])
        self.checks = table["checks"]

    @classmethod
    def from_file(cls, path) -> TableLaw:
        return cls(read_table2(path))

    @classmethod
    def from_text(cls, text: str) -> TableLaw:
        return cls(read_table2(text))

    def weights(self, ratio: float) -> tuple[np.ndarray, np.ndarray]:
        """Stencil (slice indices) and Lagrange weights in ln ρ of a contact of ratio R_2/R_1.

        Raises ValueError naming the ratio and the file's range where it lies outside it (beyond
        ``RATIO_TOLERANCE`` in ln ρ).
        """
        S = self.x.size
        if S == 1 or math.isinf(ratio) or math.isinf(self.x[-1]):
            r0 = self.slices[0].ratio
            near = (math.isfinite(ratio) and math.isfinite(r0)
                    and abs(math.log(ratio / r0)) <= RATIO_TOLERANCE)
            if not (ratio == r0 or near):
                raise ValueError(f"radius ratio R2/R1 = {ratio!r} is outside the table's range "
                                 f"[{self.slices[0].ratio!r}, {self.slices[-1].ratio!r}]")
            return np.array([0]), np.array([1.0])
        x = math.log(ratio)
        if not (self.x[0] - RATIO_TOLERANCE <= x <= self.x[-1] + RATIO_TOLERANCE):
            raise ValueError(f"radius ratio R2/R1 = {ratio!r} is outside the table's range "
                             f"[{self.slices[0].ratio!r}, {self.slices[-1].ratio!r}]")
        x = min(max(x, self.x[0]), self.x[-1])
        k = min(ORDER, S)
        j = min(int(np.searchsorted(self.x, x, side="right")) - 1, S - 2)
        i0 = min(max(j - k // 2 + 1, 0), S - k)
        idx = np.arange(i0, i0 + k)
        xs = self.x[idx]
        w = np.array([np.prod([(x - xs[b]) / (xs[a] - xs[b]) for b in range(k) if b != a])
                      for a in range(k)])
        return idx, w

    def evaluate(self, h, h_max, R1: float, R2: float):
        """F, dF/dh, a and h_1 of contacts of radii R1, R2 at approaches h with history h_max.

        Parameters
        ----------
        h, h_max : arrays (broadcast); h ≤ 0: no contact (zeros).
        R1, R2 : the radii of body 1 and body 2 (R2 = inf: a flat).

        Returns
        -------
        F, dF/dh, a, h1 : arrays shaped like the broadcast of h and h_max.
        """
        h, hm = np.broadcast_arrays(np.asarray(h, dtype=float), np.asarray(h_max, dtype=float))
        shape = h.shape
        h, hm = h.ravel(), hm.ravel()
        ratio = math.inf if math.isinf(R2) else R2 / R1
        idx, w = self.weights(ratio)
        Rs = float(_r_star(R1, R2))
        lam = [Rs / self.slices[i].Rs for i in idx]
        elastic = np.ones(h.size, dtype=bool)
        for i, lm in zip(idx, lam, strict=True):
            elastic &= hm / lm <= self.slices[i].h_elastic
        loading = (h >= hm) | elastic
        q = np.where(loading, h, hm)
        pos = q > 0.0
        qq = np.where(pos, q, 1.0)
        acc = [np.zeros(h.size) for _ in range(7)]
        for i, wi, lm in zip(idx, w, lam, strict=True):
            vals = self.slices[i].at(qq / lm)
            vals[0] = vals[0] + 2.0 * math.log(lm)
            vals[2] = vals[2] + math.log(lm)
            for a_, v in zip(acc, vals, strict=True):
                a_ += wi * v
        y, g, ya, phi, rec, m, h1r = acc
        Fq = np.exp(y)
        aq = np.exp(ya)
        F, k, a, h1 = (np.zeros(h.size) for _ in range(4))
        ld = loading & pos
        F[ld] = Fq[ld]
        k[ld] = Fq[ld] * g[ld] / q[ld]
        a[ld] = aq[ld]
        h1[ld] = phi[ld] * q[ld]
        un = ~loading & pos
        if un.any():
            delta = rec[un] * q[un]
            xi = np.clip((h[un] - q[un]) / delta + 1.0, 0.0, 1.0)
            on = xi > 0.0
            with np.errstate(divide="ignore"):
                xm1 = np.where(on, np.exp((m[un] - 1.0) * np.log(np.maximum(xi, 1e-300))), 0.0)
            F[un] = Fq[un] * xi * xm1
            k[un] = m[un] * Fq[un] * xm1 / delta
            a[un] = aq[un] * xm1
            h1_res = h1r[un] * q[un]
            h1[un] = np.where(on, h1_res + xi * (phi[un] * q[un] - h1_res), 0.0)
        return tuple(v.reshape(shape) for v in (F, k, a, h1))


def ratio_interpolation_error(lines_or_text, laws: list[ContactLaw], probes: int = 3,
                              points: int = 60) -> dict:
    """Measured error of the interpolation in ln ρ against the exact model (the probe ratio's own
    ``ContactLaw``, rtol 1e-6) at ``probes`` ratios inside every interval between slices, over
    approaches from 1e-5·h_c to h_c, the probe's calibrated range (:func:`calibrated_law`).

    Returns
    -------
    dict : ``F_loading`` (largest |ΔF|/F on the loading curve), ``F_unloading`` (largest |ΔF|/F_max
    on unloading branches from every probed peak, ξ = 0.1 … 0.9 of the elastic recovery),
    ``a_loading`` (|Δa|/a), ``ratios_probed`` and ``points`` per ratio.
    """
    text = lines_or_text if isinstance(lines_or_text, str) else "\n".join(lines_or_text) + "\n"
    tl = TableLaw.from_text(text)
    worst = {"F_loading": 0.0, "F_unloading": 0.0, "a_loading": 0.0}
    probed = []
    for lo, hi in zip(laws, laws[1:], strict=False):
        x0 = math.log(_ratio(lo.pair.s1, lo.pair.s2))
        x1 = math.log(_ratio(hi.pair.s1, hi.pair.s2))
        for f in (np.arange(1, probes + 1) / (probes + 1)):
            r = math.exp(x0 + f * (x1 - x0))
            R1 = lo.pair.s1.radius
            s1, s2 = Sphere(R1, lo.pair.s1.material), Sphere(r * R1, lo.pair.s2.material)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                ex = calibrated_law(s1, s2, coeffs=lo.pair.coeffs)  # its calibrated range
                hm = np.geomspace(1e-5 * ex.h_max, ex.h_max, points)
                F, _, a, _ = tl.evaluate(hm, hm, R1, r * R1)
                st = ex(hm)
                worst["F_loading"] = max(worst["F_loading"], float(np.max(np.abs(F / st.F - 1.0))))
                worst["a_loading"] = max(worst["a_loading"], float(np.max(np.abs(a / st.a - 1.0))))
                # unloading: ξ fractions of each peak's elastic recovery (the exact law's)
                rec = ex._peaks(hm)[3]
                xi = np.linspace(0.1, 0.9, 5)
                H = (hm[:, None] - rec[:, None] * hm[:, None] * (1.0 - xi[None, :])).ravel()
                HM = np.repeat(hm, xi.size)
                Fu = tl.evaluate(H, HM, R1, r * R1)[0]
                Fe = ex.force(H, HM)[0]
                worst["F_unloading"] = max(worst["F_unloading"],
                                           float(np.max(np.abs(Fu - Fe) / np.repeat(st.F, xi.size))))
            probed.append(r)
    return {**worst, "ratios_probed": probed, "points": points}
