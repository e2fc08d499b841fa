"""Thresholds and windows of the validation (a TOML file, ``validation/thresholds.toml``).

Keys (all optional; defaults below)::

    [window]
    h_over_R_max = 0.3          # acceptance window: end of Level I … this h/R
    h_over_R_large_max = 0.5    # second window, where the FE runs reach beyond h_over_R_max
    large_deformation_from = 0.1  # h/R above which a point counts as "large deformation"
    a_min_over_R = 0.01         # FE points with a smaller contact radius are not resolved by
                                # the mesh (pole elements 0.003 R) and are left out

    [model]                     # acceptance: largest |relative error| in the window
    F_max = 0.05
    a_max = 0.05

    [unloading]                 # acceptance of the unloading law given the FE's peak
    F_branch_max = 0.03         # largest |ΔF|/F_max along each unloading branch
    h_res_max = 0.03            # |Δh_res|/h_max

    [goal]                      # the model's design goal in the acceptance window: reported
    F_max = 0.03                # per run (section "The design goal"), never the exit status
    a_max = 0.03
    rms_max = 0.015             # RMS of the F and of the a error
    split_max = 0.05            # two bodies: |h₁/h − FE's h₁/h|
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, fields
from pathlib import Path

__all__ = ["Thresholds", "load_thresholds"]


@dataclass(frozen=True)
class Thresholds:
    h_over_R_max: float = 0.3
    h_over_R_large_max: float = 0.5
    large_deformation_from: float = 0.1
    a_min_over_R: float = 0.01
    F_max: float = 0.05
    a_max: float = 0.05
    F_branch_max: float = 0.03
    h_res_max: float = 0.03
    goal_F_max: float = 0.03
    goal_a_max: float = 0.03
    goal_rms_max: float = 0.015
    goal_split_max: float = 0.05

    def __post_init__(self) -> None:
        for name in (f.name for f in fields(self)):  # every threshold is a positive number
            v = getattr(self, name)
            if not (isinstance(v, int | float) and math.isfinite(v) and v > 0):
                raise ValueError(f"threshold {name} must be a finite number > 0, got {v!r}")
        if self.h_over_R_large_max < self.h_over_R_max:
            raise ValueError("window.h_over_R_large_max must be >= window.h_over_R_max")


_KEYS = {"window": ("h_over_R_max", "h_over_R_large_max", "large_deformation_from", "a_min_over_R"),
         "model": ("F_max", "a_max"), "unloading": ("F_branch_max", "h_res_max"),
         "goal": ("F_max", "a_max", "rms_max", "split_max")}
#: sections whose keys are stored under a prefix (``[goal] F_max`` → ``goal_F_max``)
_PREFIX = {"goal": "goal_"}


def load_thresholds(path=None) -> Thresholds:
    """Read a thresholds file (None: the defaults). Unknown sections or keys are errors."""
    if path is None:
        return Thresholds()
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text())
    except FileNotFoundError:
        raise
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as err:
        raise ValueError(f"{path}: not a valid TOML file ({err})") from err
    values = {}
    for section, content in data.items():
        if section not in _KEYS or not isinstance(content, dict):
            raise ValueError(f"{path}: unknown section [{section}] (known: {', '.join(_KEYS)})")
        for key, value in content.items():
            if key not in _KEYS[section]:
                raise ValueError(f"{path}: unknown key {section}.{key} "
                                 f"(known: {', '.join(_KEYS[section])})")
            values[_PREFIX.get(section, "") + key] = value
    try:
        return Thresholds(**values)
    except ValueError as err:
        raise ValueError(f"{path}: {err}") from err
