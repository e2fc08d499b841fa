"""``spherecontact model table``: the fast path's table as a plain .npz a DEM code evaluates alone."""

import json
import warnings

import numpy as np
import pytest
from test_model_unloading import _force_from_tables

from spherecontact.cli import main
from spherecontact.model import CalibrationRangeWarning, Material, Sphere, contact
from spherecontact.model.cli import TABLE_FORMAT, TABLE_SUFFIXES, write_table
from spherecontact.model.fast import ContactLaw

STEEL = ["--E", "210e9", "--sigma-y", "400e6", "--K", "600e6", "--n", "0.3", "--radius", "1e-3"]
ALU = ["--E2", "70e9", "--nu2", "0.33", "--sigma-y2", "100e6", "--K2", "200e6", "--n2", "0.5",
       "--radius2", "2e-3"]


def _arrays(path):
    with np.load(path) as d:
        return {k: d[k] for k in d.files}


def test_cli_table_file_evaluates_to_the_fast_path_without_the_package(tmp_path, capsys):
    out = tmp_path / "steel_alu.npz"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationRangeWarning)  # yield ratio 4: extrapolated
        assert main(["model", "table", *STEEL, *ALU, "--h-max", "2e-4", "--out", str(out)]) == 0
    assert "nodes" in capsys.readouterr().out
    tab = _arrays(out)
    meta = json.loads(str(tab["meta"]))
    assert meta["format"] == TABLE_FORMAT and meta["body2"]["radius"] == pytest.approx(2e-3)
    assert "ln_F_hermite" in meta["evaluation"] and meta["calibrated_range_warnings"]
    assert float(tab["h_max"]) == pytest.approx(2e-4)
    assert tab["ln_F_hermite"].shape == (tab["ln_h"].size - 1, 4)
    # the stored reference evaluations, reproduced from the arrays alone (loading and unloading)
    F, k = _force_from_tables(tab, tab["check_h"], tab["check_h_max"])
    np.testing.assert_allclose(F, tab["check_F"], rtol=1e-12)
    np.testing.assert_allclose(k, tab["check_dF_dh"], rtol=1e-9)
    assert np.any(tab["check_h"] < tab["check_h_max"]) and np.all(tab["check_F"] > 0)


def test_write_table_matches_a_fresh_law_and_refuses_bad_input(tmp_path):
    s1 = Sphere(1.0, Material(E=200.0, nu=0.3, sigma_y=1.0))
    flat = Sphere(np.inf, Material.rigid())
    tab = write_table(s1, flat, tmp_path / "flat.npz", h_max=0.2)
    law = ContactLaw(s1, flat, h_max=0.2)
    rng = np.random.default_rng(3)
    hm = np.exp(rng.uniform(np.log(1e-5), np.log(0.2), 500))
    h = hm * rng.uniform(0.9, 1.0, hm.size)
    np.testing.assert_allclose(_force_from_tables(_arrays(tmp_path / "flat.npz"), h, hm)[0],
                               law.force(h, hm)[0], rtol=1e-12)
    assert set(tab) >= {"ln_h", "recovery", "m", "h_elastic", "meta"}
    with pytest.raises(ValueError, match="h_max"):
        write_table(s1, flat, tmp_path / "bad.npz", h_max=-1.0)
    with pytest.raises(ValueError, match="path must end in .npz or .txt"):
        write_table(s1, flat, tmp_path / "table.csv", h_max=0.2)
    assert main(["model", "table", "--E", "200", "--sigma-y", "1", "--radius", "1", "--out",
                 str(tmp_path / "table.csv")]) == 2   # the wording: tests/test_refused_inputs.py
    assert not (tmp_path / "table.csv").exists()


def _read_text(path):
    """The .txt table read back as a code without NumPy's .npz reader would: '#' lines, then rows."""
    tab, checks = {}, []
    for line in open(path, encoding="utf-8"):
        if line.startswith("# meta: "):
            tab["meta"] = json.loads(line[len("# meta: "):])
        elif line.startswith("# h_elastic h_min h_max: "):
            tab["h_elastic"], tab["h_min"], tab["h_max"] = map(float, line.split(":")[1].split())
        elif line.startswith("# check ") and ":" not in line:
            checks.append([float(v) for v in line.split()[2:]])
    rows = np.loadtxt(path, comments="#")
    tab.update(ln_h=rows[:, 0], ln_F_hermite=rows[:-1, 1:5], recovery=rows[:, 5], m=rows[:, 6])
    return tab, np.array(checks)


def test_text_table_holds_the_same_numbers_as_the_npz(tmp_path):
    assert TABLE_SUFFIXES == (".sct", ".npz", ".txt")
    s1 = Sphere(1.0, Material(E=500.0, nu=0.3, sigma_y=1.0, K=2.0, n=0.3))
    s2 = Sphere(2.0, Material(E=900.0, nu=0.25, sigma_y=3.0))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CalibrationRangeWarning)
        npz = write_table(s1, s2, tmp_path / "pair.npz", h_max=0.3)
        write_table(s1, s2, tmp_path / "pair.txt", h_max=0.3)
    tab, checks = _read_text(tmp_path / "pair.txt")
    # standard JSON for readers without Infinity/NaN (a flat's radius is the string "inf")
    flat = write_table(s1, Sphere(np.inf, Material.rigid()), tmp_path / "flat.txt", h_max=0.3)

    def refuse(name):
        raise ValueError(f"non-standard JSON constant {name}")
    meta = json.loads(str(flat["meta"]), parse_constant=refuse)
    assert meta["body2"]["radius"] == "inf" and meta["body2"]["E"] == "inf"
    assert tab["meta"]["format"] == TABLE_FORMAT and tab["meta"]["nodes"] == npz["ln_h"].size
    assert np.isnan(np.loadtxt(tmp_path / "pair.txt", comments="#")[-1, 1:5]).all()
    for key in ("ln_h", "ln_F_hermite", "recovery", "m", "h_elastic", "h_min", "h_max"):
        np.testing.assert_array_equal(tab[key], npz[key])  # 17 digits: the same doubles
    assert checks.shape == (npz["check_h"].size, 4)
    F, k = _force_from_tables(tab, checks[:, 0], checks[:, 1])
    np.testing.assert_allclose(F, checks[:, 2], rtol=1e-12)
    np.testing.assert_allclose(k, checks[:, 3], rtol=1e-9)


def test_curve_takes_a_flow_table_for_either_body(tmp_path, capsys):
    """``model curve --flow-table`` / ``--flow-table2`` give the API's pair of tabulated bodies."""
    t1, t2 = tmp_path / "steel.csv", tmp_path / "alu.csv"
    t1.write_text("eps_p,sigma\n0,400e6\n0.05,520e6\n0.3,650e6\n")
    t2.write_text("# aluminium\n0,120e6\n0.02,160e6\n0.4,230e6\n")
    assert main(["model", "curve", "--E", "210e9", "--flow-table", str(t1), "--radius", "1e-3",
                 "--E2", "70e9", "--nu2", "0.33", "--flow-table2", str(t2), "--radius2", "2e-3",
                 "--h-max", "1e-4", "--points", "5", "--json", "--out", str(tmp_path / "c.json")]) == 0
    got = json.loads((tmp_path / "c.json").read_text())
    steel = Material.from_table(210e9, 0.3, [0, 0.05, 0.3], [400e6, 520e6, 650e6])
    alu = Material.from_table(70e9, 0.33, [0, 0.02, 0.4], [120e6, 160e6, 230e6])
    st = contact(Sphere(1e-3, steel), Sphere(2e-3, alu), np.asarray(got["h"]))
    np.testing.assert_allclose(got["F"], st.F, rtol=1e-12)
    np.testing.assert_allclose(got["h1"], st.h1, rtol=1e-12)
    assert got["meta"]["body2"]["sigma_table"] == [120e6, 160e6, 230e6]
