"""Campaign format v2: space-filling samples, tabulated and saturating flow curves, unloading
cycles and the surface band; the shipped v2 design."""

from pathlib import Path

import numpy as np
import pytest

from spherecontact.campaign.design import load_campaign, parse_campaign
from spherecontact.data import Database

ROOT = Path(__file__).resolve().parents[1]
HEAD = '[defaults]\nh_max = 0.3\n'
SOBOL = '''
[[s]]
scene = "flat"
sample = { method = "sobol", n = 8, seed = 3 }
E_over_sigma_y = { log = [10, 10000] }
K_over_sigma_y = { range = [0, 10] }
n = 0.3
'''


def test_sample_is_seeded_space_filling_and_in_range():
    a = parse_campaign(HEAD + SOBOL).cases
    b = parse_campaign(HEAD + SOBOL).cases
    assert [c.key for c in a] == [c.key for c in b]  # same seed, same design
    E = np.array([c.params["E_over_sigma_y"] for c in a])
    K = np.array([c.params["K_over_sigma_y"] for c in a])
    assert len(a) == 8 and np.all((E >= 10) & (E <= 10000)) and np.all((K >= 0) & (K <= 10))
    # space filling: every decade of E/σY and every quarter of K holds points
    assert set(np.floor(np.log10(E)).astype(int)) == {1, 2, 3}
    assert len(set(np.floor(K / 2.5).astype(int))) == 4
    other = parse_campaign(HEAD + SOBOL.replace("seed = 3", "seed = 4")).cases
    assert {c.key for c in other}.isdisjoint({c.key for c in a})


@pytest.mark.parametrize("old, new, message", [
    ("n = 8", "n = 6", "power of 2"),
    ("{ log = [10, 10000] }", "{ log = [0, 10] }", "E_over_sigma_y must be"),
    ('method = "sobol"', 'method = "grid"', "sample.method"),
])
def test_bad_samples_are_named(old, new, message):
    with pytest.raises(ValueError, match=message):
        parse_campaign(HEAD + SOBOL.replace(old, new))


def test_range_without_sample_is_an_error():
    with pytest.raises(ValueError, match="no sample"):
        parse_campaign(HEAD + '[[s]]\nscene = "flat"\nE_over_sigma_y = { log = [10, 100] }\n')


CURVE = '''
[flow_curves.metal]
source = "a handbook"
eps_p = [0, 0.1, 1.0]
sigma_over_sigma_y = [1, 1.5, 2.0]
[[s]]
scene = "flat"
flow_curve = "metal"
E_over_sigma_y = 500
'''


def test_named_flow_curve_becomes_a_table():
    (case,) = parse_campaign(HEAD + CURVE).cases
    assert case.inputs["material"]["sigma_table"] == [1.0, 1.5, 2.0]
    assert case.run_kwargs()["material"].is_tabulated
    assert case.name.startswith("flat-metal-E500")
    with pytest.raises(ValueError, match="'steel' is not a table"):
        parse_campaign(HEAD + CURVE.replace('flow_curve = "metal"', 'flow_curve = "steel"'))
    with pytest.raises(ValueError, match="replaces K_over_sigma_y"):
        parse_campaign(HEAD + CURVE + "K_over_sigma_y = 2\n")
    with pytest.raises(ValueError, match="must start at 1"):
        parse_campaign(HEAD + CURVE.replace("[1, 1.5, 2.0]", "[2, 2.5, 3.0]"))


def test_voce_saturation_is_tabulated_accurately():
    (case,) = parse_campaign(HEAD + '[[s]]\nscene = "flat"\nE_over_sigma_y = 300\n'
                                    'Q_over_sigma_y = 2\nb = 20\n').cases
    mat = case.run_kwargs()["material"]
    eps = np.geomspace(1e-4, 2.0, 200)
    exact = 1.0 + 2.0 * (1.0 - np.exp(-20.0 * eps))
    assert np.max(np.abs(mat.flow_stress(eps) / exact - 1)) < 2e-3
    assert "voceQ2-b20" in case.name


def test_voce_table_keys_do_not_depend_on_the_last_bit_of_numpy(monkeypatch):
    """NumPy's SIMD exp/power differ in the last bit between CPUs; the table is rounded, so a
    one-ulp change of the computed curve leaves the run's key as it is."""
    text = HEAD + '[[s]]\nscene = "flat"\nE_over_sigma_y = 300\nK_over_sigma_y = 1.3\nn = 0.27\n' \
                  'Q_over_sigma_y = 2.9\nb = 36.4\n'
    (case,) = parse_campaign(text).cases
    expm1 = np.expm1
    monkeypatch.setattr(np, "expm1", lambda x: np.nextafter(expm1(x), np.inf))
    (bumped,) = parse_campaign(text).cases
    assert bumped.key == case.key
    table = case.inputs["material"]["sigma_table"]
    assert all(float(f"{v:.10g}") == v for v in table)


def test_cycles_scale_with_the_smaller_radius_and_defaults_keep_old_keys():
    text = HEAD + 'cycles = [0.01, 0.1, 0.3]\nedge_band = 0.03\n[[s]]\nscene = "rigid_sphere"\n' \
                  'indenter_radius = 0.5\nE_over_sigma_y = 100\n'
    (case,) = parse_campaign(text).cases
    assert case.inputs["h_max"] == pytest.approx(0.15)
    assert case.inputs["unload_at"] == pytest.approx([0.005, 0.05, 0.15])
    assert case.run_kwargs()["edge_band"] == 0.03
    (plain,) = parse_campaign(HEAD + '[[s]]\nscene = "flat"\nE_over_sigma_y = 100\n').cases
    assert "unload_at" not in plain.inputs and "edge_band" not in plain.inputs
    assert "band_floor" not in case.inputs and case.run_kwargs()["band_floor"] is None
    with pytest.raises(ValueError, match="cycles must increase"):
        parse_campaign(text.replace("[0.01, 0.1, 0.3]", "[0.1, 0.01]"))


def test_a_band_floor_other_than_the_default_names_the_case_and_enters_its_key():
    pair = HEAD + 'edge_band = 0.03\n[[s]]\nscene = "two_body"\nE_over_sigma_y = 200\nradius2 = 0.333\n'
    (plain,) = parse_campaign(pair).cases
    (floored,) = parse_campaign(pair + "band_floor = 0.003\n").cases
    assert floored.name == plain.name + "-f0.003" and floored.key != plain.key
    assert floored.inputs["band_floor"] == 0.003 and floored.run_kwargs()["band_floor"] == 0.003
    (default,) = parse_campaign(pair + "band_floor = 0.0005\n").cases
    assert default.key == plain.key and default.name == plain.name
    with pytest.raises(ValueError, match="band_floor"):
        parse_campaign(pair + "band_floor = 0.01\n")
    with pytest.raises(ValueError, match="needs a surface band"):
        parse_campaign(pair.replace("edge_band = 0.03", "edge_band = 0") + "band_floor = 0.003\n")


def test_v2_campaign_keys_match_its_database():
    """Every case of the shipped v2 design is in the v2 database under its key, name and set, and
    the database holds nothing else; the designed cases the campaign replaced are not in it."""
    db = Database(ROOT / "data" / "reference_v2.h5")
    text = (ROOT / "data" / "campaign_v2.toml").read_text()
    cases = load_campaign(ROOT / "data" / "campaign_v2.toml").cases
    records = {rec.key: rec for rec in db.records(status=None)}
    assert len(cases) == len(records) == 142
    assert [c.name for c in cases if c.key not in db] == []
    assert set(records) == {c.key for c in cases}
    assert all((records[c.key].case, records[c.key].set) == (c.name, c.set) for c in cases)
    # the design without its [replace] tables: the replaced cases are not in the database
    designed = parse_campaign(text[:text.index("\n[replace.")]).cases
    replaced = {c.replaces[0] for c in cases if c.replaces}
    assert len(replaced) == 3
    assert sorted(c.name for c in designed if c.key not in db) == sorted(replaced)


def test_shipped_v2_design():
    c = load_campaign(ROOT / "data" / "campaign_v2.toml")
    cal, val = c.select({"calibration"}), c.select({"validation"})
    assert len(cal) >= 80 and len(val) >= 30
    assert not {x.key for x in cal} & {x.key for x in val}
    designed = [x for x in c.cases if not x.replaces]
    assert all(x.params["h_max"] == 0.3 and len(x.inputs["unload_at"]) == 4 for x in designed)
    # a replaced case says why, and is short of the design only where the FE stops
    replaced = [x for x in c.cases if x.replaces]
    assert len(replaced) <= 6 and all(x.replaces[1] for x in replaced)
    assert all(0.04 <= x.params["h_max"] <= 0.3 for x in replaced)
    metals = {x.params["flow_curve"] for x in val if x.params["flow_curve"]}
    assert len(metals) >= 3 and not any(x.params["flow_curve"] for x in cal)
    ratios = {round(x.params.get("indenter_radius", x.params.get("radius2", 1)), 3) for x in val}
    assert {3.0, 0.333} <= ratios
    assert any(x.params.get("sigma_y2_over_sigma_y1") == 5 for x in val)
    assert any(x.params["K_over_sigma_y"] == 5 for x in val)
    E = [x.params["E_over_sigma_y"] for x in cal]
    assert min(E) == 10 and max(E) == 10000


def test_plan_runs_the_cheapest_cases_first():
    from spherecontact.campaign.driver import plan

    cases = parse_campaign(HEAD + '[[s]]\nscene = "flat"\nE_over_sigma_y = [10000, 10, 300]\n'
                                  '[[s]]\nscene = "two_body"\nE_over_sigma_y = 30\n'
                                  'E2_over_E1 = 3\noptions = { penalty = 100 }\n').cases
    order = [c.name.split("-")[0] + "-" + c.name.split("-")[2] for c in plan(list(cases), None)]
    assert order == ["flat-E10", "flat-E300", "two-E30", "flat-E10000"]  # cost 3, 17, 55, 100


GRID = ('[defaults]\nh_max = 0.3\ncycles = [0.01, 0.1, 0.3]\n'
        '[[s]]\nscene = "flat"\nE_over_sigma_y = [100, 1000]\n')


def test_a_replaced_case_leaves_the_campaign_and_its_replacement_says_why():
    designed = {c.name: c for c in parse_campaign(GRID).cases}
    text = GRID + '[replace."flat-pp-E1000-nu0.3"]\nh_max = 0.2\nreason = "inverted element"\n'
    cases = {c.name: c for c in parse_campaign(text).cases}
    assert set(cases) == {"flat-pp-E100-nu0.3", "flat-pp-E1000-nu0.3-h0.2"}
    new = cases["flat-pp-E1000-nu0.3-h0.2"]
    assert new.replaces == ("flat-pp-E1000-nu0.3", "inverted element")
    assert new.inputs["h_max"] == 0.2 and new.inputs["unload_at"] == [0.01, 0.1]
    assert cases["flat-pp-E100-nu0.3"].key == designed["flat-pp-E100-nu0.3"].key
    assert cases["flat-pp-E100-nu0.3"].replaces == ()
    # cycles alone: same name, another key
    text = GRID + '[replace."flat-pp-E100-nu0.3"]\ncycles = [0.01, 0.1]\nreason = "x"\n'
    (c,) = [c for c in parse_campaign(text).cases if c.name == "flat-pp-E100-nu0.3"]
    assert c.key != designed[c.name].key and c.inputs["unload_at"] == [0.01, 0.1]


@pytest.mark.parametrize("entry, message", [
    ('[replace."flat-pp-E10-nu0.3"]\nh_max = 0.2\nreason = "x"\n', "no case of the campaign"),
    ('[replace."flat-pp-E100-nu0.3"]\nh_max = 0.2\n', "needs a reason"),
    ('[replace."flat-pp-E100-nu0.3"]\nreason = "x"\n', "nothing to replace"),
    ('[replace."flat-pp-E100-nu0.3"]\nnu = 0.2\nreason = "x"\n', "'nu' cannot be replaced"),
    ('[replace."flat-pp-E100-nu0.3"]\nh_max = 2\nreason = "x"\n', "h_max"),
    ('[replace."flat-pp-E100-nu0.3"]\ncycles = [0.3, 0.1]\nreason = "x"\n', "cycles must increase"),
])
def test_bad_replacements_are_named(entry, message):
    with pytest.raises(ValueError, match=message):
        parse_campaign(GRID + entry)
