"""``spherecontact fem run``: end to end on tiny runs, early stop, bad input, help texts."""

import math
import time

import numpy as np
import pytest

from spherecontact.cli import main
from spherecontact.fem import cli as fcli
from spherecontact.fem import io as fio
from spherecontact.fem import read_run
from spherecontact.model.material import Material

TINY = ["--mesh-density", "0.25", "--dh-first", "1e-3", "--dh-max", "0.005", "--quiet"]
EPP = ["--E", "200", "--nu", "0.3", "--sigma-y", "1", "--K", "0", "--n", "1"]


def fem_run(*args) -> int:
    return main(["fem", "run", *args])


def test_run_rigid_flat_end_to_end(tmp_path, capsys):
    out = tmp_path / "run.h5"
    code = fem_run(*EPP, "--radius", "1", "--h-max", "0.01", "--out", str(out), *TINY)
    assert code == 0
    printed = capsys.readouterr().out
    assert str(out) in printed and "converged" in printed and "Newton" in printed
    run = read_run(out)
    assert run.status == "converged"
    assert run.h[-1] == pytest.approx(0.01, rel=1e-12)
    assert np.all(np.diff(run.h) > 0) and np.all(np.diff(run.F) > 0)
    assert run.a[-1] > 0
    assert run.material() == Material(E=200.0, nu=0.3, sigma_y=1.0, K=0.0, n=1.0)
    assert math.isinf(run.inputs["indenter_radius"])
    assert run.inputs["mesh_density"] == 0.25 and run.inputs["element"] == "q8r"
    assert run.inputs["options"]["dh_max"] == 0.005
    assert f"{run.F[-1]:.6g}" in printed


def test_edge_band_reaches_the_mesh(tmp_path):
    # the reference campaigns' surface band (edge_band 0.03) is available from the command line
    runs = {}
    for band in ("0", "0.03"):
        out = tmp_path / f"band{band}.h5"
        assert fem_run(*EPP, "--h-max", "0.002", "--edge-band", band, "--out", str(out), *TINY) == 0
        runs[band] = read_run(out)
    assert runs["0.03"].inputs["edge_band"] == 0.03 and runs["0"].inputs.get("edge_band", 0.0) == 0.0
    assert runs["0.03"].inputs["n_dofs"] > runs["0"].inputs["n_dofs"]


def test_run_rigid_sphere_with_flow_table(tmp_path):
    table = tmp_path / "flow.csv"
    table.write_text("# copper-like curve\neps_p,sigma\n0,1\n0.05,1.5\n0.2,2.0\n")
    out = tmp_path / "sphere.h5"
    code = fem_run("--E", "200", "--nu", "0.34", "--flow-table", str(table), "--radius", "2",
                   "--indenter-radius", "3", "--h-max", "0.01", "--out", str(out), *TINY)
    assert code == 0
    run = read_run(out)
    assert run.inputs["indenter_radius"] == 3.0 and run.inputs["radius"] == 2.0
    assert run.material() == Material.from_table(200.0, 0.34, [0, 0.05, 0.2], [1, 1.5, 2.0])
    assert run.provenance["extra"]["flow_table"] == str(table)
    assert run.h[-1] == pytest.approx(0.01)


def test_run_that_stops_early_is_written_and_flagged(tmp_path, capsys):
    """Two Newton iterations cannot reach the tolerance: the run stops, exit code 3."""
    out = tmp_path / "stopped.h5"
    code = fem_run(*EPP, "--h-max", "0.01", "--max-iterations", "2", "--tol", "1e-14",
                   "--out", str(out), *TINY)
    assert code == fcli.EXIT_STOPPED == 3
    err = capsys.readouterr().err
    assert "stopped" in err and "dh_min" in err
    run = read_run(out)
    assert run.status == "stopped" and "dh_min" in run.reason
    assert run.reason in err


class _NoSolver:
    def __init__(self, *args, **kwargs):
        raise AssertionError("the solver must not be built for invalid inputs")


BAD = {
    "nu": (["--E", "200", "--nu", "0.5", "--sigma-y", "1", "--h-max", "0.1"], "nu"),
    "nu_high": (["--E", "200", "--nu", "0.7", "--h-max", "0.1"], "nu"),
    "E": (["--E", "-3", "--h-max", "0.1"], "E (Young's modulus)"),
    "radius": (["--E", "200", "--radius", "-1", "--h-max", "0.1"], "radius"),
    "h_max_zero": (["--E", "200", "--h-max", "0"], "h_max"),
    "h_max_negative": (["--E", "200", "--h-max", "-0.1"], "h_max"),
    "h_max_large": (["--E", "200", "--h-max", "0.9"], "h_max"),
    "density_low": (["--E", "200", "--h-max", "0.1", "--mesh-density", "0.1"], "mesh density"),
    "density_high": (["--E", "200", "--h-max", "0.1", "--mesh-density", "8"], "mesh density"),
    "indenter": (["--E", "200", "--h-max", "0.1", "--indenter-radius", "-2"], "indenter_radius"),
    "sigma_y": (["--E", "200", "--sigma-y", "0", "--h-max", "0.1"], "sigma_y"),
    "dh": (["--E", "200", "--h-max", "0.1", "--dh-first", "0.5"], "dh_first"),
    "iterations": (["--E", "200", "--h-max", "0.1", "--max-iterations", "1"], "max_iterations"),
    "tol": (["--E", "200", "--h-max", "0.1", "--tol", "0"], "tol"),
    "edge_band": (["--E", "200", "--h-max", "0.1", "--edge-band", "0.5"], "edge_band"),
    "band_floor": (["--E", "200", "--h-max", "0.1", "--edge-band", "0.03", "--band-floor", "0.1"],
                   "band_floor"),
}


@pytest.mark.parametrize("case", BAD)
def test_bad_input_exit_2_before_any_work(case, tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(fio, "IndentationSolver", _NoSolver)
    args, name = BAD[case]
    out = tmp_path / "run.h5"
    t0 = time.perf_counter()
    code = fem_run(*args, "--out", str(out), "--quiet")
    assert time.perf_counter() - t0 < 1.0
    assert code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and name in err
    assert not out.exists()


@pytest.mark.parametrize("content, message", [
    ("eps_p,sigma\n0,1\n0.1,2\n0.2,1.5\n", "non-decreasing"),
    ("0,1\n0.1,2\n0.1,3\n", "strictly increasing"),
    ("0.01,1\n0.1,2\n", "start at 0"),
    ("0,1\n", "at least 2"),
    ("0,1,5\n0.1,2,6\n", "two columns"),
    ("0,1\n0.1,abc\n", "line 2"),
    ("# only a comment\n", "no data"),
])
def test_bad_flow_table(content, message, tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(fio, "IndentationSolver", _NoSolver)
    table = tmp_path / "flow.csv"
    table.write_text(content)
    code = fem_run("--E", "200", "--flow-table", str(table), "--h-max", "0.1",
                   "--out", str(tmp_path / "r.h5"))
    assert code == 2
    err = capsys.readouterr().err
    assert "--flow-table" in err and message in err


@pytest.mark.parametrize("extra, message", [
    (["--flow-table", "missing.csv"], "cannot read"),
    (["--flow-table", "x.csv", "--sigma-y", "1"], "--sigma-y"),
])
def test_flow_table_usage_errors(extra, message, tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(fio, "IndentationSolver", _NoSolver)
    monkeypatch.chdir(tmp_path)
    code = fem_run("--E", "200", *extra, "--h-max", "0.1", "--out", "r.h5")
    assert code == 2 and message in capsys.readouterr().err


def test_output_directory_must_exist(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(fio, "IndentationSolver", _NoSolver)
    code = fem_run("--E", "200", "--h-max", "0.1", "--out", str(tmp_path / "no" / "r.h5"))
    assert code == 2 and "--out" in capsys.readouterr().err


def test_flow_table_reader_accepts_header_comments_and_spaces(tmp_path):
    table = tmp_path / "flow.csv"
    table.write_text("# measured\n eps_p , sigma \n\n0, 100\n0.1 ,150\n# end\n")
    eps, sigma = fcli.read_flow_table(table)
    np.testing.assert_array_equal(eps, [0.0, 0.1])
    np.testing.assert_array_equal(sigma, [100.0, 150.0])


RUN_OPTIONS = ["--E", "--nu", "--sigma-y", "--K", "--n", "--flow-table", "--radius", "--h-max",
               "--indenter-radius", "--mesh-density", "--element", "--dh-first", "--dh-max",
               "--dh-min", "--max-iterations", "--tol", "--out", "--quiet"]


@pytest.mark.parametrize("argv", [["fem", "--help"], ["fem", "run", "--help"]])
def test_help_describes_every_option(argv, capsys):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 0
    text = capsys.readouterr().out
    for opt in RUN_OPTIONS:
        assert opt in text, opt
    for rng in ("(-1, 0.5)", "(0, 0.8 min(R, R2)]", "[0.25, 4]", "[2, 200]", "unit of --radius"):
        assert rng in text, rng


def test_solver_option_flags_reach_the_options():
    from spherecontact.cli import build_parser
    from spherecontact.fem.cli import options_from_args

    args = build_parser().parse_args([
        "fem", "run", "--E", "200", "--h-max", "0.1", "--out", "x.h5", "--strain-increment", "0.002",
        "--max-wall-s", "10", "--no-line-search"])
    opts = options_from_args(args)
    assert opts.strain_increment == 0.002 and opts.max_wall_s == 10.0 and opts.line_search is False
    default = options_from_args(build_parser().parse_args(
        ["fem", "run", "--E", "200", "--h-max", "0.1", "--out", "x.h5"]))
    assert default.line_search is True and default.max_wall_s == float("inf")


def test_body_2_takes_its_own_flow_table(tmp_path):
    """``fem run --flow-table2``: body 2 of a two-body run is the tabulated material, checked like
    body 1's; body 1's flow curve is untouched."""
    from spherecontact.cli import build_parser, join_negative_values
    from spherecontact.model.cli_args import material2_from_args, material_from_args

    table = tmp_path / "alu.csv"
    table.write_text("eps_p,sigma\n0,1.2\n0.02,1.6\n0.4,2.3\n")
    args = build_parser().parse_args(join_negative_values(
        ["fem", "run", *EPP, "--E2", "70", "--nu2", "0.33", "--flow-table2", str(table),
         "--h-max", "0.01", "--out", str(tmp_path / "r.h5")]))
    m1 = material_from_args(args)
    m2 = material2_from_args(args, m1)
    assert m1 == Material(E=200.0, nu=0.3, sigma_y=1.0)
    assert m2 == Material.from_table(70.0, 0.33, [0.0, 0.02, 0.4], [1.2, 1.6, 2.3])
