"""The increment-converged first loading of a stored run, where the contact is still small.

The loading increments are bounded by the strain per step, dh ≤ strain_increment · a
(``SolverOptions``), which allows dh/h ≈ 0.01 c² R/a: about 0.6 at a/R = 0.02, ten increments a
decade of h across the elastic–plastic transition of a stiff sphere. The plastic path taken
over such steps differs from the converged one. This re-runs the first loading of stored
cases, up to the campaign's first unloading approach (``H_END`` of the smaller radius), with
the increments also bounded by the approach, dh ≤ r · h (``SolverOptions.relative_step``), and
compares F and a with the stored curve at its own approaches (loading increments after the
first ones, ``io.reference_mask``; log–log interpolation of the new curve), per decade of h.

The validation set's re-runs are stored as data (``spherecontact campaign increments``, the
database side in ``spherecontact.campaign.increments``) and read by the validation's
small-contact section; ``studies/fem_increments_study.py`` runs other windows and bounds.
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path

import numpy as np

from ..metrics import interp_loglog
from ..model.material import Material
from .io import loading_mask, run_indentation
from .solver import SolverOptions

#: the re-run ends at the campaign's first unloading approach (units of the smaller radius)
H_END = 0.01
RELATIVE_STEP = 0.03
#: a is compared where the contact spans several elements, a ≥ A_RESOLVED × the smaller radius
#: (the calibration's filter on the default mesh): below, the fitted edge lies within a pole element
A_RESOLVED = 0.01


def smaller_radius(inputs: dict) -> float:
    """The body's radius or its rigid partner's, the smaller: the length of ``H_END``."""
    return min(float(inputs["radius"]), float(inputs.get("indenter_radius", math.inf)))


def read_reruns(path) -> tuple[dict, dict]:
    """``(key → re-run case, header)`` of a re-run file (``spherecontact campaign increments``,
    :func:`spherecontact.campaign.increments.collect`); the header holds ``h_end``,
    ``date_utc``, ``db`` and ``note`` (what the calibration's ``--converged-fe`` and the validation's
    small-contact section read)."""
    d = json.loads(Path(path).read_text())
    return {c["key"]: c for c in d.pop("cases")}, d


def rerun(inputs: dict, relative_step: float | None, h_end: float = H_END,
          strain_increment: float | None = None):
    """The first loading of a stored one-body case to ``h_end`` (units of the smaller radius),
    increments dh ≤ ``relative_step`` · h (None: no such bound) and dh ≤ ``strain_increment`` · a
    (None: the solver's)."""
    strain = {} if strain_increment is None else {"strain_increment": strain_increment}
    return run_indentation(Material.from_description(inputs["material"]), float(inputs["radius"]),
                           h_end * smaller_radius(inputs),
                           indenter_radius=float(inputs.get("indenter_radius", math.inf)),
                           edge_band=float(inputs.get("edge_band", 0.0)),
                           band_floor=inputs.get("band_floor"),
                           options=SolverOptions(relative_step=relative_step, **strain))


def by_decade(h_old, y_old, h_new, y_new, length: float) -> dict:
    """ln(stored/new) of y at the stored approaches, largest |·| per decade of h/``length``
    (keys: the decade's lower end) and over all."""
    dev = np.log(y_old / interp_loglog(h_old, h_new, y_new))
    k = np.floor(np.log10(h_old / length) + 1e-12).astype(int)
    out = {f"1e{d}": float(dev[k == d][np.argmax(np.abs(dev[k == d]))]) for d in np.unique(k)}
    out["largest"] = float(dev[np.argmax(np.abs(dev))])
    out["mean"] = {f"1e{d}": float(dev[k == d].mean()) for d in np.unique(k)}
    return out


def measure_run(inputs: dict, run, relative_step: float | None, h_end: float = H_END,
                strain_increment: float | None = None) -> dict:
    """Re-run the first loading of the stored one-body ``run`` (a ``fem.io.Run`` of these
    ``inputs``) with :func:`rerun` and compare: ln(stored/new) of F and a per decade of h
    (:func:`by_decade`, a where a ≥ ``A_RESOLVED`` × the smaller radius), the increment counts,
    the wall time and the new curve (8 significant digits)."""
    old = {"h": np.asarray(run.h), "F": np.asarray(run.F), "a": np.asarray(run.a)}
    keep = np.asarray(run.reference)  # loading increments without a first step's transient
    L = smaller_radius(inputs)
    t = time.perf_counter()
    new = rerun(inputs, relative_step, h_end, strain_increment)
    wall = time.perf_counter() - t
    keep &= (old["h"] >= new.h[0]) & (old["h"] <= new.h[-1])
    ka = keep & (old["a"] >= A_RESOLVED * L)
    return {"relative_step": relative_step,
            "strain_increment": strain_increment, "wall_s": round(wall, 1),
            "stored_increments": int(np.count_nonzero(old["h"][loading_mask(run.curves)] <= h_end * L)),
            "new_increments": int(new.h.size),
            "F": by_decade(old["h"][keep], old["F"][keep], new.h, new.F, L),
            "a": by_decade(old["h"][ka], old["a"][ka], new.h, new.a, L) if ka.any() else None,
            "curve": {q: [float(f"{v:.8g}") for v in getattr(new, q)] for q in ("h", "F", "a")}}
