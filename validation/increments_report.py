"""The model against FE curves converged in the increment size where the contact is small.

``spherecontact campaign increments`` (``fem/increments.py``) re-runs the first loading of the
one-body validation runs, up to h/R = 0.01, with increments dh ≤ 0.03 h as well as the strain
bound, and stores those curves as data (``data/increments_v2.json``). The stored campaign curves
lie below them by up to several per cent where the contact is small (fem/README.md, "Increments where
the contact is small"); this section reads the model's error over the acceptance window up to
h/R = 0.01 against both, so that an error there is not mistaken for the model's alone. The
thresholds are read against the stored curves as before; this section decides nothing.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..fem.increments import read_reruns
from ..metrics import interp_loglog
from .compare import W_ACCEPT, Comparison

__all__ = ["load_converged", "small_contact_rows", "small_contact_section"]

#: the file ``spherecontact campaign increments`` writes for the validation set
DEFAULT_PATH = Path("data/increments_v2.json")


def load_converged(path=DEFAULT_PATH) -> dict | None:
    """key → (h, F) of the re-run curves, with the file's ``h_end`` and ``relative_step`` under
    ``"_meta"``; None when the file is absent."""
    path = Path(path)
    if not path.exists():
        return None
    cases, head = read_reruns(path)
    out = {k: (np.asarray(c["curve"]["h"]), np.asarray(c["curve"]["F"])) for k, c in cases.items()}
    steps = {c["relative_step"] for c in cases.values()}
    out["_meta"] = {"h_end": float(head["h_end"]), "relative_step": steps.pop() if len(steps) == 1 else None,
                    "date": head.get("date_utc"), "path": str(path)}
    return out


def small_contact_rows(comps: list[Comparison], store: dict) -> list[dict]:
    """Per run with a converged curve: over the acceptance window up to ``h_end`` (the smaller
    radius), the largest |stored/converged − 1| of F and the model's largest |error| of F against
    each, with the h/R where it sits."""
    h_end = store["_meta"]["h_end"]
    rows = []
    for c in comps:
        if c.case.key not in store:
            continue
        hc, Fc = store[c.case.key]
        h = c.case.h
        m = c.masks[W_ACCEPT] & (c.h_over_R <= h_end * (1 + 1e-9)) & (h >= hc[0]) & (h <= hc[-1])
        if np.count_nonzero(m) < 2:
            continue
        F_fe, F_model, hR = c.case.F[m], c.model.F[m], c.h_over_R[m]
        F_conv = interp_loglog(h[m], hc, Fc)
        errs = {"fe": F_fe / F_conv - 1.0, "model_stored": F_model / F_fe - 1.0,
                "model_converged": F_model / F_conv - 1.0}
        rows.append({"run": c.case.label, "points": int(m.sum())}
                    | {k: _largest(e, hR) for k, e in errs.items()})
    return rows


def _largest(e: np.ndarray, hR: np.ndarray) -> tuple[float, float]:
    """The error of largest magnitude and the h/R where it sits."""
    i = int(np.argmax(np.abs(e)))
    return float(e[i]), float(hR[i])


def small_contact_section(comps: list[Comparison], store: dict | None) -> list[str]:
    """Markdown lines of the section (a note only when the converged curves are absent)."""
    head = ["## The model where the contact is small, against increment-converged FE", ""]
    if store is None:
        return head + ["No converged curves (`make verify-increments`, "
                       f"`{DEFAULT_PATH}`): not compared.", ""]
    meta = store["_meta"]
    rows = small_contact_rows(comps, store)
    worse = [r for r in rows if abs(r["model_converged"][0]) > abs(r["model_stored"][0])]
    lines = head + [
        f"The first loading of {len(rows)} one-body runs re-run to h/R = {meta['h_end']:g} with increments "
        f"dh ≤ {meta['relative_step']} h (`{meta['path']}`, {meta['date']}); over the acceptance window up "
        f"to that h/R: the stored curve against the converged one, and the model against each (largest "
        f"|error| %, at h/R). The model is closer to the converged curve on {len(rows) - len(worse)} of "
        f"{len(rows)} runs. Thresholds are read against the stored curves (section \"Verdict\").", "",
        "| run | points | stored/converged − 1 | model vs stored | model vs converged |",
        "|---|---|---|---|---|"]
    for r in sorted(rows, key=lambda r: -abs(r["fe"][0])):
        cell = lambda v: f"{100 * v[0]:+.1f} ({v[1]:.1g})"  # noqa: E731
        lines.append(f"| {r['run']} | {r['points']} | {cell(r['fe'])} | {cell(r['model_stored'])} "
                     f"| {cell(r['model_converged'])} |")
    return lines + [""]
