"""The design goal section: raw against smoothed FE, what each run misses, the [goal] keys."""

import math

import numpy as np
import pytest

from spherecontact.validation.cases import Case
from spherecontact.validation.compare import compare_case
from spherecontact.validation.config import Thresholds, load_thresholds
from spherecontact.validation.goal import goal_rows, goal_section
from tests.test_validation import PP200, make_case

TH = Thresholds()
H = np.geomspace(2e-4, 0.3, 80)


def _with_F(case: Case, factor) -> Case:
    """The case with its FE force multiplied point by point."""
    curves = dict(case.curves, F=case.curves["F"] * factor)
    return Case(case.key, case.set, case.name, case.params, case.inputs, curves,
                wall_s=case.wall_s, provenance=case.provenance)


def test_goal_keys_are_read_under_their_own_section(tmp_path):
    th = load_thresholds("validation/thresholds.toml")
    assert (th.goal_F_max, th.goal_a_max, th.goal_rms_max, th.goal_split_max) == (0.03, 0.03, 0.015, 0.05)
    assert th.F_max == 0.05  # [model] F_max is not overwritten by [goal] F_max
    f = tmp_path / "t.toml"
    f.write_text("[goal]\nF_max = 0.02\n")
    assert load_thresholds(f).goal_F_max == 0.02 and load_thresholds(f).F_max == 0.05
    for text, named in (("F_maks = 0.02", "goal.F_maks"), ("rms_max = 0", "goal_rms_max")):
        f.write_text(f"[goal]\n{text}\n")
        with pytest.raises(ValueError, match=named):
            load_thresholds(f)


def test_a_smooth_offset_misses_raw_and_smoothed_alike():
    off = compare_case(make_case("off", h=H, scale_F=1 / 1.04), None, TH)  # model 4 % above
    (row,) = goal_rows([off])
    assert row.F.max == pytest.approx(0.04, rel=1e-9)
    assert row.F_smooth.max == pytest.approx(0.04, abs=0.003)  # the smoothing of the kinks at the levels
    assert row.misses(TH) == ["F max", "F rms"] and row.misses(TH, smooth=True) == ["F max", "F rms"]
    assert math.isnan(row.split)


def test_increment_scatter_alone_misses_raw_but_not_smoothed():
    """A ±3.5 % sawtooth on the FE force: the model (exact) misses 3 % against the stored curve
    and meets it against the smoothed one."""
    saw = 1.0 + 0.035 * (-1.0) ** np.arange(H.size)
    noisy = compare_case(_with_F(make_case("noisy", h=H), saw), None, TH)
    (row,) = goal_rows([noisy])
    assert row.F.max > 0.03 and "F max" in row.misses(TH)
    assert row.F_smooth.max < 0.02 and row.misses(TH, smooth=True) == []
    text = "\n".join(goal_section([row], TH))
    assert "missed on 1 of 1 runs" in text and "smoothed out" in text and "on 0." in text
    assert "| noisy | F max, F rms |" in text


def test_split_counts_for_two_bodies_and_a_met_goal_is_said():
    two = compare_case(make_case("pair", scene="two_body", radius2=2.0, h=H,
                                 material2={**PP200, "sigma_y": 2.0}), None, TH)
    (row,) = goal_rows([two])
    assert row.split < 1e-9 and row.misses(TH) == []
    assert goal_section([row], TH)[0].endswith("**met on all 1 runs**.")
    case = two.case
    shifted = Case(case.key, case.set, case.name, case.params, case.inputs,
                   dict(case.curves, h1=case.curves["h1"] - 0.08 * case.curves["h"]),
                   wall_s=case.wall_s, provenance=case.provenance)
    (row,) = goal_rows([compare_case(shifted, None, TH)])
    assert row.split == pytest.approx(0.08, rel=1e-6) and row.misses(TH) == ["split"]
