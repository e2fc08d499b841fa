"""FE campaign: campaign-file parsing and validation, failed and stopped runs, resume after
SIGKILL, and the same campaign on a Dask cluster."""

import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from spherecontact.campaign import driver as fc
from spherecontact.campaign.design import PARAMETERS, load_campaign, parse_campaign
from spherecontact.data import Database, input_key

ROOT = Path(__file__).resolve().parents[1]
TINY = """
[defaults]
h_max = {h_max}
mesh_density = 0.25
options = {{dh_first = 0.001, dh_max = 0.005}}
"""



def campaign_run(argv: list[str]) -> int:
    """``spherecontact campaign run ARGV``."""
    from spherecontact.cli import main

    return main(["campaign", "run", *argv])

def tiny(body: str, h_max: float = 0.01) -> str:
    return TINY.format(h_max=h_max) + body


# ---------------------------------------------------------------------------- parsing
def test_grid_expansion_names_and_inputs():
    c = parse_campaign(tiny("""
[[calibration]]
scene = "flat"
K_over_sigma_y = 2
n = [0.15, 0.3]
E_over_sigma_y = [100, 1000]
nu = 0.45

[[validation]]
scene = "rigid_sphere"
indenter_radius = 0.5
E_over_sigma_y = 200

[[validation]]
scene = "two_body"
E_over_sigma_y = 200
radius2 = 2
sigma_y2_over_sigma_y1 = 3
"""))
    assert c.sets == ("calibration", "validation")
    names = [x.name for x in c.cases]
    assert names == ["flat-K2-n0.15-E100-nu0.45", "flat-K2-n0.15-E1000-nu0.45", "flat-K2-n0.3-E100-nu0.45",
                     "flat-K2-n0.3-E1000-nu0.45", "rsphere0.5-pp-E200-nu0.3", "two-pp-E200-nu0.3-vs-R2-sy3"]
    flat = c.cases[1]
    assert flat.params["E_over_sigma_y"] == 1000 and flat.params["n"] == 0.15
    assert flat.inputs["material"] == {"E": 1000.0, "nu": 0.45, "sigma_y": 1.0, "K": 2.0, "n": 0.15}
    assert math.isinf(flat.inputs["indenter_radius"]) and flat.inputs["options"]["dh_max"] == 0.005
    assert flat.key == input_key(flat.inputs)
    assert c.cases[4].inputs["indenter_radius"] == 0.5
    two = c.cases[5]
    assert two.inputs["radius2"] == 2.0 and two.inputs["h_max"] == 0.01  # h_max in min(R1, R2)
    assert two.inputs["material2"] == {"E": 200.0, "nu": 0.3, "sigma_y": 3.0, "K": 0.0, "n": 1.0}
    kw = two.run_kwargs()
    assert kw["radius2"] == 2.0 and kw["material2"].sigma_y == 3.0 and "indenter_radius" not in kw
    assert math.isinf(kw["options"].max_wall_s)
    assert [x.name for x in c.select({"validation"}, only="two")] == ["two-pp-E200-nu0.3-vs-R2-sy3"]


def test_max_wall_s_is_a_limit_not_an_input():
    a = parse_campaign(tiny('[[s]]\nscene = "flat"\nE_over_sigma_y = 100\n')).cases[0]
    b = parse_campaign(tiny('[[s]]\nscene = "flat"\nE_over_sigma_y = 100\nmax_wall_s = 5\n')).cases[0]
    assert a.key == b.key and b.max_wall_s == 5 and b.run_kwargs()["options"].max_wall_s == 5


@pytest.mark.parametrize("body, message", [
    ('[[calibration]]\nscene = "flat"\nE_over_sigma_y = 100\nyoung = 3\n',
     r"\[\[calibration\]\] entry 1: unknown parameter 'young'"),
    ('[[calibration]]\nscene = "flat"\nE_over_sigma_y = 100\nnu = [0.3, 0.5]\n',
     r"\[\[calibration\]\] entry 1: nu = 0.5 out of range: must lie in \(-1, 0.5\)"),
    ('[[calibration]]\nscene = "flat"\nE_over_sigma_y = 0\n',
     r"entry 1: E_over_sigma_y = 0 out of range: must lie in \(1, 1e\+07\]"),
    ('[[calibration]]\nscene = "flat"\nE_over_sigma_y = -5\n', r"E_over_sigma_y = -5 out of range"),
    ('[[calibration]]\nscene = "flat"\n', r"entry 1: parameter E_over_sigma_y is required"),
    ('[[calibration]]\nscene = "cube"\nE_over_sigma_y = 100\n', r"scene = 'cube' is not one of"),
    ('[[calibration]]\nscene = "flat"\nE_over_sigma_y = 100\nindenter_radius = 2\n',
     r"parameter indenter_radius applies to scene rigid_sphere only, not 'flat'"),
    ('[[calibration]]\nscene = "rigid_sphere"\nE_over_sigma_y = 100\n',
     r"parameter indenter_radius is required"),
    ('[[calibration]]\nscene = "flat"\nE_over_sigma_y = "big"\n', r"E_over_sigma_y must be a number"),
    ('[[calibration]]\nscene = "flat"\nE_over_sigma_y = []\n', r"E_over_sigma_y is an empty list"),
    ('[[calibration]]\nscene = "flat"\nE_over_sigma_y = 100\noptions = {tol = -1}\n',
     r"entry 1: options: tol must be a finite number > 0"),
    ('[[calibration]]\nscene = "flat"\nE_over_sigma_y = 100\noptions = {max_wall_s = 1}\n',
     r"unknown solver option 'max_wall_s' \(max_wall_s is a parameter of its own\)"),
    ('[[calibration]]\nscene = "flat"\nE_over_sigma_y = [100, 300]\n'
     '[[validation]]\nscene = "flat"\nE_over_sigma_y = [50, 300]\n',
     r"case flat-pp-E300-nu0.3 appears in both sets: \[\[calibration\]\] entry 1 and "
     r"\[\[validation\]\] entry 1"),
    ('[[calibration]]\nscene = "flat"\nE_over_sigma_y = 100\nK_over_sigma_y = [0, 0]\n',
     r"case flat-pp-E100-nu0.3 appears twice"),
    ("", r"no sets"),
])
def test_campaign_errors_name_the_entry_and_parameter(body, message):
    with pytest.raises(ValueError, match=r"^test.toml: .*" + message):
        parse_campaign(tiny(body), source="test.toml")


def test_defaults_are_checked():
    with pytest.raises(ValueError, match=r"\[defaults\]: h_max = 0.9 out of range: must lie in \(0, 0.8\]"):
        parse_campaign(tiny('[[s]]\nscene = "flat"\nE_over_sigma_y = 100\n', h_max=0.9))
    with pytest.raises(ValueError, match=r"top-level key 'h_max' must be a set, an array of tables "
                                         r"\(\[\[h_max\]\]\); parameters go in \[defaults\]"):
        parse_campaign('h_max = 0.1\n[[s]]\nscene = "flat"\nE_over_sigma_y = 100\n')
    with pytest.raises(ValueError, match="not valid TOML"):
        parse_campaign("[[s]\n")


def test_campaign_v1_design():
    """Campaign v1's design (its database retired from the tree) still parses to its 35 cases."""
    c = load_campaign(ROOT / "studies" / "campaign_v1.toml")
    cal, val = c.select({"calibration"}), c.select({"validation"})
    assert (len(cal), len(val)) == (22, 13)
    assert not {x.key for x in cal} & {x.key for x in val}
    assert {x.scene for x in cal} == {"flat", "rigid_sphere"}
    assert sum(x.scene == "two_body" for x in val) == 6
    assert all(x.params["h_max"] == 0.3 for x in c.cases)
    penalty = {x.name for x in c.cases if x.inputs["options"].get("penalty")}
    assert penalty == {f"two-pp-E200-nu0.3-vs-{s}" for s in ("R2", "R4", "E600")}  # equal hardness
    long = penalty | {f"flat-pp-E{e}-nu0.3" for e in (50, 500, 5000, 10, 30, 100, 300, 1000, 3000, 10000)}
    assert all(x.max_wall_s == (5400 if x.name in long else 900) for x in c.cases)
    assert set(PARAMETERS) | {"cycles"} >= {k for x in c.cases for k in x.params}


# ---------------------------------------------------------------------------- running
def failing(case):
    """A runner whose runs all raise (recorded as failed by execute's handler)."""
    raise RuntimeError(f"no solver for {case.name}")


def test_failed_run_is_recorded_and_retried(tmp_path, capsys):
    c = parse_campaign(tiny('[[calibration]]\nscene = "flat"\nE_over_sigma_y = [100, 200]\n'))
    db_path = tmp_path / "ref.h5"

    def runner(case):
        return fc.execute(case) if case.name.startswith("flat-pp-E100") else \
            fc.Outcome(case.key, "failed", "RuntimeError: no solver", 0.0, traceback="Traceback ...")

    summary = fc.run_campaign(c, db_path, workers=0, runner=runner)
    assert summary["total"] == {**summary["total"], "cases": 2, "converged": 1, "failed": 1}
    db = Database(db_path)
    (fail,) = db.failed()
    assert fail.case == "flat-pp-E200-nu0.3" and fail.reason == "RuntimeError: no solver"
    assert [r.case for r, _ in db.runs()] == ["flat-pp-E100-nu0.3"]
    assert db.campaign["text"] == c.text
    saved = json.loads(Path(f"{db_path}.summary.json").read_text())
    assert saved["sets"]["calibration"]["failed"] == 1 and saved["content_hash"] == db.content_hash
    # without --retry-failed nothing runs again; with it the failure is replaced
    assert fc.run_campaign(c, db_path, workers=0, runner=failing)["ran"] == 0
    summary = fc.run_campaign(c, db_path, workers=0, retry_failed=True)
    assert summary["ran"] == 1 and summary["total"]["converged"] == 2
    assert Database(db_path).failed() == []


def test_exceptions_in_the_solver_become_failed_outcomes():
    c = parse_campaign(tiny('[[calibration]]\nscene = "flat"\nE_over_sigma_y = 100\n'))
    case = c.cases[0]
    object.__setattr__(case, "inputs", {**case.inputs, "element": "q9"})  # bypass the file checks
    out = fc.execute(case)
    assert out.status == "failed" and out.result is None
    assert "element must be one of" in out.reason and "Traceback" in out.traceback


def test_stopped_run_is_stored_apart_and_rerun_on_request(tmp_path):
    body = '[[calibration]]\nscene = "flat"\nE_over_sigma_y = 100\nmax_wall_s = {}\n'
    db_path = tmp_path / "ref.h5"
    summary = fc.run_campaign(parse_campaign(tiny(body.format(0.001), h_max=0.02)), db_path, workers=0)
    assert summary["total"]["stopped"] == 1
    db = Database(db_path)
    assert db.runs() == [] and len(db.runs(status="stopped")) == 1
    (rec,) = db.records(status="stopped")
    assert "wall-time limit" in rec.reason
    longer = parse_campaign(tiny(body.format(600), h_max=0.02))  # same key: max_wall_s is no input
    assert fc.run_campaign(longer, db_path, workers=0)["ran"] == 0
    summary = fc.run_campaign(longer, db_path, workers=0, retry_stopped=True)
    assert summary["ran"] == 1 and summary["total"]["converged"] == 1
    db = Database(db_path)
    assert len(db) == 1 and db.run(rec.key).status == "converged"


def test_dry_run_and_exit_codes(tmp_path, capsys):
    toml = tmp_path / "c.toml"
    toml.write_text(tiny('[[calibration]]\nscene = "flat"\nE_over_sigma_y = [100, 200]\n'))
    db = tmp_path / "ref.h5"
    assert campaign_run(["--campaign", str(toml), "--db", str(db), "--dry-run"]) == 0
    out = capsys.readouterr().out
    assert "flat-pp-E200-nu0.3" in out and "calibration: 2 cases (2 missing)" in out
    assert not db.exists()
    assert campaign_run(["--campaign", str(toml), "--db", str(db), "--set", "validation"]) == 2
    assert "--set validation: the campaign has the sets calibration" in capsys.readouterr().err
    assert campaign_run(["--campaign", str(tmp_path / "none.toml"), "--db", str(db)]) == 2
    assert campaign_run(["--campaign", str(toml), "--db", str(db), "--workers", "0", "--only", "E100"]) == 0
    out = capsys.readouterr().out
    assert "calibration" in out and "wall/run" in out
    assert [r.case for r in Database(db).records()] == ["flat-pp-E100-nu0.3"]


def test_superseded_entries_are_listed_and_pruned(tmp_path, capsys):
    body = '[[calibration]]\nscene = "flat"\nE_over_sigma_y = [100, 200]\n'
    toml = tmp_path / "c.toml"
    toml.write_text(tiny(body))
    db_path = tmp_path / "ref.h5"
    fc.run_campaign(load_campaign(toml), db_path, workers=0,
                    runner=lambda case: fc.execute(case) if "E100" in case.name else
                    fc.Outcome(case.key, "failed", "RuntimeError: no solver", 0.0))
    assert campaign_run(["--campaign", str(toml), "--db", str(db_path), "--prune"]) == 0
    assert "0 superseded entries removed" in capsys.readouterr().out
    h = Database(db_path).content_hash
    assert campaign_run(["--campaign", str(toml), "--db", str(db_path), "--compact"]) == 0
    assert f"{db_path}: " in capsys.readouterr().out and Database(db_path).content_hash == h
    # new solver options give both cases new keys: the old run and the old failure are superseded
    toml.write_text(tiny(body).replace("dh_max = 0.005", "dh_max = 0.004"))
    changed = load_campaign(toml)
    old = fc.superseded(changed, Database(db_path))
    assert sorted((r.case, r.status) for r in old) == [("flat-pp-E100-nu0.3", "converged"),
                                                        ("flat-pp-E200-nu0.3", "failed")]
    assert campaign_run(["--campaign", str(toml), "--db", str(db_path), "--dry-run"]) == 0
    out = capsys.readouterr().out
    assert "2 superseded database entries" in out and "calibration: 2 cases (2 missing)" in out
    assert campaign_run(["--campaign", str(toml), "--db", str(db_path), "--prune"]) == 0
    assert "2 superseded entries removed" in capsys.readouterr().out
    db = Database(db_path)
    assert len(db) == 0 and db.failed() == [] and fc.superseded(changed, db) == []


def test_workers_report_progress_and_the_folder_is_removed(tmp_path, monkeypatch):
    c = parse_campaign(tiny('[[calibration]]\nscene = "flat"\nE_over_sigma_y = [100, 200]\n'))
    folder = tmp_path / "progress"
    folder.mkdir()
    monkeypatch.setenv(fc.PROGRESS_ENV, str(folder))
    case = c.cases[0]
    assert fc.execute(case).status == "converged"
    (frac,) = fc.read_progress(folder, c.cases).values()    # the case that ran, not the other
    assert 0.0 < frac <= 1.0 + 1e-12
    monkeypatch.delenv(fc.PROGRESS_ENV)
    db_path = tmp_path / "ref.h5"
    seen = []
    (tmp_path / "p2").mkdir()
    stream = fc._local(c.cases, fc.execute, 1, tmp_path / "p2", seen.append)
    assert sorted(o.status for _, o in stream) == ["converged", "converged"]
    assert not (tmp_path / "p2").exists()                    # removed when the workers are done
    assert all(isinstance(running, list) for running in seen)
    assert fc.run_campaign(c, db_path, workers=1)["total"]["converged"] == 2
    assert not list(tmp_path.glob(".ref.h5.progress*"))


def test_progress_reports_never_fail_a_run_and_campaigns_keep_their_own(tmp_path, monkeypatch):
    """A second campaign on the same database (a retry of one case) used to clear the shared
    progress folder when it finished; every run of the first then failed with
    FileNotFoundError at its next report (campaign v2: 25 runs lost, one after 400 s)."""
    c = parse_campaign(tiny('[[calibration]]\nscene = "flat"\nE_over_sigma_y = 100\n'))
    monkeypatch.setenv(fc.PROGRESS_ENV, str(tmp_path / "gone"))  # the folder does not exist
    assert fc.execute(c.cases[0]).status == "converged"
    db_path = tmp_path / "ref.h5"
    mine = fc.progress_folder(db_path)
    assert mine.name == f".ref.h5.progress.{os.getpid()}"
    live = tmp_path / f".ref.h5.progress.{os.getppid()}"  # another campaign that still runs
    dead_pid = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                              capture_output=True, text=True, check=True).stdout.strip()
    dead, legacy = tmp_path / f".ref.h5.progress.{dead_pid}", tmp_path / ".ref.h5.progress"
    for folder in (live, dead, legacy):
        folder.mkdir()
    assert sorted(fc.remove_stale_progress(db_path)) == sorted([dead, legacy])
    assert live.is_dir()


def test_remove_entries_rejects_unknown_keys_and_keeps_the_rest(tmp_path):
    from spherecontact.data import remove_entries
    c = parse_campaign(tiny('[[calibration]]\nscene = "flat"\nE_over_sigma_y = [100, 200]\n'))
    db_path = tmp_path / "ref.h5"
    fc.run_campaign(c, db_path, workers=0)
    keep, drop = (x.key for x in c.cases)
    before = Database(db_path).run(keep)
    with pytest.raises(ValueError, match="no entry with key 0123456789abcdef"):
        remove_entries(db_path, [drop, "0123456789abcdef"])
    assert len(Database(db_path)) == 2  # nothing removed
    (gone,) = remove_entries(db_path, [drop])
    db = Database(db_path)
    assert gone.key == drop and list(db) == [keep]
    assert (db.run(keep).F == before.F).all() and db.campaign["text"] == c.text


# ---------------------------------------------------------------------------- kill and resume
def _entries(path: Path) -> int:
    try:
        return len(Database(path))
    except (FileNotFoundError, ValueError):
        return 0


def test_killed_campaign_resumes(tmp_path):
    toml = tmp_path / "c.toml"
    toml.write_text(tiny('[[calibration]]\nscene = "flat"\nE_over_sigma_y = [100, 120, 150, 200]\n',
                         h_max=0.02))
    db_path = tmp_path / "ref.h5"
    cmd = [sys.executable, "-m", "spherecontact.cli", "campaign", "run", "--campaign", str(toml),
           "--db", str(db_path), "--workers", "1"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)
    try:
        deadline = time.monotonic() + 120
        while _entries(db_path) < 1:
            assert proc.poll() is None, proc.stderr.read().decode()
            assert time.monotonic() < deadline, "the campaign wrote nothing in 120 s"
            time.sleep(0.02)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)  # the campaign and its worker
        proc.communicate()
    assert proc.returncode == -signal.SIGKILL
    db = Database(db_path)  # readable; every stored run complete
    first = {k: db.run(k).provenance for k in db}
    assert 1 <= len(first) < 4 and all(db.record(k).status == "converged" for k in db)

    resumed = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert resumed.returncode == 0, resumed.stderr
    assert f"4 cases selected, {len(first)} already in" in resumed.stderr
    db = Database(db_path)
    names = sorted(r.case for r in db.records())
    assert names == ["flat-pp-E100-nu0.3", "flat-pp-E120-nu0.3", "flat-pp-E150-nu0.3", "flat-pp-E200-nu0.3"]
    assert len(db.runs()) == 4
    for key, prov in first.items():  # not redone
        assert db.run(key).provenance == prov
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]


# ---------------------------------------------------------------------------- Dask
def test_campaign_on_a_dask_cluster(tmp_path):
    distributed = pytest.importorskip("dask.distributed")
    c = parse_campaign(tiny('[[calibration]]\nscene = "flat"\nE_over_sigma_y = 100\n'
                            '[[validation]]\nscene = "rigid_sphere"\nindenter_radius = 2\n'
                            'E_over_sigma_y = 100\n'))
    db_path = tmp_path / "ref.h5"
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        summary = fc.run_campaign(c, db_path, scheduler=cluster.scheduler_address)
    assert summary["backend"].startswith("dask tcp://") and summary["total"]["converged"] == 2
    db = Database(db_path)
    assert [(r.set, r.case) for r, _ in db.runs()] == [("calibration", "flat-pp-E100-nu0.3"),
                                                       ("validation", "rsphere2-pp-E100-nu0.3")]
    _, run = db.runs(set="validation")[0]
    assert run.inputs["indenter_radius"] == 2.0
    assert run.provenance["extra"]["entry_point"] == "spherecontact campaign run"


def test_a_result_the_writer_rejects_fails_its_case_not_the_campaign(tmp_path):
    """Campaign v2: a two-body result with more profile rows than increments raised in the
    writer and ended the whole campaign; now that case is recorded as failed (or, when a
    stopped run of it is stored, that run is kept) and the other cases are stored."""
    c = parse_campaign(tiny('[[calibration]]\nscene = "flat"\nE_over_sigma_y = [100, 200]\n'))
    db_path = tmp_path / "ref.h5"

    def runner(case):
        out = fc.execute(case)
        if case.name.startswith("flat-pp-E200"):
            r = out.result
            r.profile_r = r.profile_r[:-1]   # one row short: the writer rejects it
        return out

    summary = fc.run_campaign(c, db_path, workers=0, runner=runner)
    assert summary["total"] == {**summary["total"], "cases": 2, "converged": 1, "failed": 1}
    (fail,) = Database(db_path).failed()
    assert fail.case == "flat-pp-E200-nu0.3" and fail.reason.startswith("result could not be stored")
    assert "profile_r" in fail.reason


def test_a_retry_that_gets_no_further_keeps_the_stored_stopped_run(tmp_path):
    """Campaign v2: a retried two-body pair stopped at h/R = 0.046 and replaced the stored run
    that had reached 0.073. A retry that does not converge replaces the stored run only when it
    gets further; one that fails keeps it too."""
    body = '[[calibration]]\nscene = "flat"\nE_over_sigma_y = 100\nmax_wall_s = {}\n'
    db_path = tmp_path / "ref.h5"
    fc.run_campaign(parse_campaign(tiny(body.format(0.001), h_max=0.02)), db_path, workers=0)
    (rec,) = Database(db_path).records(status="stopped")
    h_stored = Database(db_path).run(rec.key).h.copy()

    def short(case):   # stops at once: no further than the stored run
        r = fc.execute(case).result
        r.curves = {k: v[:1] for k, v in r.curves.items()}
        r.residuals = r.residuals[:1]
        r.profile_r, r.profile_p, r.profile_g = r.profile_r[:1], r.profile_p[:1], r.profile_g[:1]
        return fc.Outcome(case.key, "stopped", "increment below dh_min (test)", 0.1, r)

    def failing(case):
        return fc.Outcome(case.key, "failed", "RuntimeError: boom", 0.0, traceback="Traceback ...")

    again = parse_campaign(tiny(body.format(600), h_max=0.02))
    for runner in (short, failing):
        summary = fc.run_campaign(again, db_path, workers=0, retry_stopped=True, runner=runner)
        assert summary["ran"] == 1 and summary["total"]["stopped"] == 1
        db = Database(db_path)
        assert db.failed() == [] and np.array_equal(db.run(rec.key).h, h_stored)


def test_refresh_start_reruns_runs_made_with_an_old_first_step(tmp_path, monkeypatch):
    """A run whose first step crossed first yield (made before the first-yield bound) is
    re-run by --refresh-start and replaced when the re-run converges; a run with today's first
    step is not; a re-run that fails keeps the stored converged run."""
    from spherecontact.fem import solver as fs
    from spherecontact.fem.io import start_steps

    body = '[[calibration]]\nscene = "flat"\nE_over_sigma_y = [1000, 10]\n'
    c = parse_campaign(tiny(body, h_max=0.002))
    db_path = tmp_path / "ref.h5"
    today = fs.first_step
    with monkeypatch.context() as m:  # the rule before the bound: no first-yield cut
        m.setattr(fs, "first_step", lambda opt, length, scale, h_y: today(opt, length, scale, 1.0))
        fc.run_campaign(c, db_path, workers=0)
    db = Database(db_path)
    stiff, soft = (next(r for r in db.records() if f"E{e}-" in r.case) for e in (1000, 10))
    h1_old = db.run(stiff.key).h[0]
    assert h1_old > start_steps(stiff.inputs)[0] and fc.old_start(db, stiff.key)
    assert not fc.old_start(db, soft.key)  # its first increment stayed elastic
    assert [x.key for x in fc.plan(list(c.cases), db, refresh_start=True)] == [stiff.key]

    def failing(case):
        return fc.Outcome(case.key, "failed", "RuntimeError: boom", 0.0, traceback="Traceback ...")

    summary = fc.run_campaign(c, db_path, workers=0, refresh_start=True, runner=failing)
    assert summary["ran"] == 1 and Database(db_path).run(stiff.key).h[0] == h1_old
    summary = fc.run_campaign(c, db_path, workers=0, refresh_start=True)
    db = Database(db_path)
    assert summary["ran"] == 1 and summary["total"]["converged"] == 2 and len(db) == 2
    assert db.run(stiff.key).h[0] == start_steps(stiff.inputs)[0] < h1_old
    assert fc.plan(list(c.cases), db, refresh_start=True) == []
