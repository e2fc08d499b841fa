"""The validation's own study runs on disk: the speed–accuracy chart and the stability section
read them when the database holds no ``studies`` set (the report then names this source).

Each is a JSON file ``<name>.json`` with ``inputs``, ``curves``, ``status``, ``reason`` and
``timings`` (``studies/validation_fem_reports.py`` writes them into
``data/validation_studies``: variants of the standard case, E/σ_Y = 200, h/R = 0.3).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from .cases import Case

__all__ = ["load_study_files"]


def _case(name: str, d: dict, inputs: dict, source: str) -> Case:
    curves = {k: np.asarray(v, dtype=float) for k, v in d["curves"].items()}
    wall = float(d.get("timings", {}).get("wall_s", math.nan))
    params = {"scene": "flat", "mesh_density": float(inputs.get("mesh_density", 1.0)),
              "strain_increment": float(inputs.get("options", {}).get("strain_increment", 0.005)),
              "element": inputs.get("element", "q8r")}
    return Case(key=f"file:{name}", set="studies", name=name, params=params, inputs=inputs,
                curves=curves, status=d.get("status", "converged"), reason=d.get("reason", ""),
                wall_s=wall, provenance={"timings": d.get("timings", {}), "wall_s": wall,
                                         "source": source})


def load_study_files(directory) -> list[Case]:
    """Cases of the study-run files ``directory/*.json`` (empty list if none)."""
    out = []
    for path in sorted(Path(directory).glob("*.json")):
        try:
            d = json.loads(path.read_text())
            out.append(_case(path.stem, d, d["inputs"], str(path)))
        except (OSError, ValueError, KeyError, TypeError):
            continue
    return out
