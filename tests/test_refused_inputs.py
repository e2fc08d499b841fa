"""Inputs that are surely wrong are refused before any work, with a message naming the
parameter, its value and the likely cause: exit code 2 on the command line, ValueError (or
TypeError for a missing argument) in the API. ``ROWS`` is the table of refused inputs."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from spherecontact.cli import join_negative_values, main
from spherecontact.model import ContactLaw, Material, Sphere, load_coefficients

PLASTIC = ["--E", "200", "--nu", "0.3", "--sigma-y", "1"]
CURVE = ["model", "curve", "--radius", "1", "--h-max", "0.1"]
RUN = ["fem", "run", "--radius", "1", "--h-max", "0.01", "--mesh-density", "0.25", "--quiet"]

#: flow tables written to the test's directory: name → CSV text
TABLES = {
    "mpa.csv": "eps_p,sigma\n0,250\n0.1,300\n0.5,350\n",          # MPa against E in Pa
    "percent.csv": "eps_p,sigma\n0,250e6\n2,300e6\n20,350e6\n",   # strains in per cent
    "good.csv": "eps_p,sigma\n0,250e6\n0.1,300e6\n0.5,350e6\n",
}

#: (id, command line, words the message must contain); {tmp} is the test's directory
ROWS = [
    ("E in Pa, sigma_y in MPa", [*CURVE, "--E", "200e9", "--sigma-y", "400"],
     ["E/sigma_y = 5e+08", "[5, 1e+06]", "different units"]),
    ("E/sigma_y below 5", [*CURVE, "--E", "2", "--sigma-y", "1"], ["E/sigma_y = 2 ", "[5, 1e+06]"]),
    ("body 2 E/sigma_y in other units", [*CURVE, *PLASTIC, "--E2", "70e9", "--sigma-y2", "100"],
     ["body 2", "E/sigma_y = 7e+08"]),
    ("flow table in MPa, E in Pa", [*CURVE, "--E", "210e9", "--flow-table", "{tmp}/mpa.csv"],
     ["--flow-table", "E/sigma[0] = 8.4e+08", "different units"]),
    ("flow-table strains in per cent", [*CURVE, "--E", "210e9", "--flow-table", "{tmp}/percent.csv"],
     ["eps_p reaches 20", "per cent"]),
    ("body 2 flow table in per cent",
     [*CURVE, "--E", "210e9", "--flow-table", "{tmp}/good.csv", "--flow-table2", "{tmp}/percent.csv"],
     ["--flow-table2", "per cent"]),
    ("Ludwik n = 0 with K > 0", [*CURVE, *PLASTIC, "--K", "2", "--n", "0"],
     ["n = 0 with K = 2.0", "sigma_y + K = 3.0", "write sigma_y = 3.0, K = 0"]),
    ("K without a yield stress", [*CURVE, "--E", "200", "--K", "2"], ["--K/--n need --sigma-y"]),
    ("flow table beside --sigma-y",
     [*CURVE, "--E", "210e9", "--sigma-y", "1e8", "--flow-table", "{tmp}/good.csv"],
     ["--flow-table replaces", "drop --sigma-y"]),
    ("negative E in scientific notation", [*CURVE, "--E", "-193e9", "--sigma-y", "1"],
     ["E (Young's modulus) must be > 0", "-193000000000.0"]),
    ("negative nu in scientific notation", [*CURVE, *PLASTIC[:2], "--nu", "-1.5e0", "--sigma-y", "1"],
     ["nu (Poisson's ratio) must lie in (-1, 0.5)", "-1.5"]),
    ("approach beyond the model's domain", ["model", "curve", *PLASTIC, "--radius", "1", "--h-max", "5"],
     ["h = 5", "outside the model's domain"]),
    ("curve --out into a missing directory", [*CURVE, *PLASTIC, "--out", "{tmp}/missing/c.csv"],
     ["--out", "missing", "does not exist"]),
    ("table --out with a CSV suffix", ["model", "table", *PLASTIC, "--radius", "1", "--out", "{tmp}/t.csv"],
     ["--out", "t.csv", ".npz or .txt"]),
    ("missing coefficient file", [*CURVE, *PLASTIC, "--coefficients", "{tmp}/none.json"],
     ["coefficients: cannot read", "none.json"]),
    ("coefficient file not JSON", [*CURVE, *PLASTIC, "--coefficients", "{tmp}/mpa.csv"],
     ["coefficients: cannot read", "not valid JSON"]),
    ("fem run --out with a text suffix", [*RUN, *PLASTIC, "--out", "{tmp}/x.txt"],
     ["--out", "x.txt", ".h5 or .hdf5"]),
    ("fem run --out into a missing directory", [*RUN, *PLASTIC, "--out", "{tmp}/missing/r.h5"],
     ["does not exist"]),
    ("fem run E in GPa, sigma_y in Pa", [*RUN, "--E", "200", "--sigma-y", "250e6", "--out", "{tmp}/r.h5"],
     ["E/sigma_y = 8e-07", "different units"]),
    ("fem run body 2 Ludwik n = 0", [*RUN, *PLASTIC, "--K2", "1", "--n2", "0", "--out", "{tmp}/r.h5"],
     ["body 2", "n = 0 with K = 1.0"]),
    ("fem run body 2 flow table in per cent",
     [*RUN, *PLASTIC, "--E2", "210e9", "--flow-table2", "{tmp}/percent.csv", "--out", "{tmp}/r.h5"],
     ["--flow-table2", "per cent"]),
    ("fem run negative h-max in scientific notation", [*RUN[:4], "--h-max", "-1e-2", *PLASTIC,
                                                        "--out", "{tmp}/r.h5"],
     ["h_max must lie in", "-0.01"]),
]


def _argv(row_args, tmp) -> list[str]:
    return [a.replace("{tmp}", str(tmp)) for a in row_args]


@pytest.fixture
def tables(tmp_path):
    for name, text in TABLES.items():
        (tmp_path / name).write_text(text)
    return tmp_path


@pytest.mark.parametrize("name, args, words", ROWS, ids=[r[0] for r in ROWS])
def test_refused_on_the_command_line(name, args, words, tables, capsys):
    code = main(_argv(args, tables))
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.startswith("spherecontact: error: ") and "Traceback" not in err
    for w in words:
        assert w.replace("{tmp}", str(tables)) in err, (w, err)
    assert not (tables / "r.h5").exists() and not (tables / "t.csv").exists()


def test_the_table_has_at_least_fifteen_rows():
    assert len(ROWS) >= 15 and len({r[0] for r in ROWS}) == len(ROWS)


def test_negative_values_are_joined_to_their_flag_only():
    assert join_negative_values(["--E", "-193e9", "--nu", "-.3", "--h-max", "0.1"]) == \
        ["--E=-193e9", "--nu=-.3", "--h-max", "0.1"]
    assert join_negative_values(["--E=-1", "-2"]) == ["--E=-1", "-2"]


def test_warnings_print_their_message_only(capsys):
    warnings.simplefilter("default")  # this suite ignores the range warnings (pyproject.toml)
    code = main(["model", "curve", *PLASTIC, "--radius", "1", "--radius2", "inf", "--E2", "inf",
                 "--h-max", "0.5", "--points", "2"])
    err = capsys.readouterr().err
    assert code == 0
    lines = err.strip().splitlines()
    assert len(lines) == 2 and all(x.startswith("spherecontact: warning: ") for x in lines), err
    assert "h/R = 0.5" in err and "warnings.warn" not in err and ".py:" not in err


def test_material_without_a_yield_stress_is_not_silently_elastic():
    with pytest.raises(TypeError, match="sigma_y"):
        Material(E=200.0, nu=0.3)  # pylint: disable=no-value-for-parameter
    assert math.isinf(Material.elastic(200.0, 0.3).sigma_y)


def test_the_api_refuses_what_the_command_line_refuses():
    with pytest.raises(ValueError, match=r"E/sigma_y = 5e\+08 .* different units"):
        Material(E=200e9, nu=0.3, sigma_y=400.0)
    with pytest.raises(ValueError, match="n = 0 with K = 2.0"):
        Material(E=200.0, nu=0.3, sigma_y=1.0, K=2.0, n=0.0)
    with pytest.raises(ValueError, match="per cent"):
        Material.from_table(210e9, 0.3, [0.0, 2.0, 20.0], [250e6, 300e6, 350e6])
    with pytest.raises(ValueError, match=r"E/sigma\[0\] = 8\.4e\+08"):
        Material.from_table(210e9, 0.3, [0.0, 0.1], [250.0, 300.0])
    Material(E=5.0, nu=0.3, sigma_y=1.0)       # the limits themselves are allowed
    Material(E=1e6, nu=0.3, sigma_y=1.0)
    Material(E=200.0, nu=0.3, sigma_y=1.0, K=0.0, n=0.0)   # n = 0 without K: perfectly plastic


def test_contact_law_force_needs_its_history():
    law = ContactLaw(Sphere(1.0, Material(E=200.0, nu=0.3, sigma_y=1.0)), Sphere(math.inf, Material.rigid()))
    h = np.array([0.05, 0.1])
    with pytest.raises(TypeError, match="h_max"):
        law.force(h)  # pylint: disable=no-value-for-parameter
    F_load, k_load = law.loading_force(h)
    F, k = law.force(h, h)
    np.testing.assert_allclose(F, F_load, rtol=1e-9)
    F_un, _ = law.force(np.array([0.099]), 0.1)
    assert F_un[0] < law.loading_force(0.099)[0]   # unloading is below the loading curve


def test_literature_set_only_by_name():
    assert load_coefficients().source == "calibration"
    assert load_coefficients("literature").source == "literature"
