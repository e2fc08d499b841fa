"""Design of a campaign at a glance: its points in parameter space and its table of runs.

``spherecontact campaign design --campaign data/campaign_v2.toml
--db data/reference_v2.h5 --out reports/campaign`` (:func:`write_design`) writes

* ``design.png``: the cases in the planes (E/σY, K/σY), (E/σY, n), (E/σY, R2/R1),
  (K/σY, n), calibration and validation in different markers, per scene;
* ``design.md`` / ``design.json``: parameter ranges per set and scene, the runs per set
  and scene with their state in the database (converged / stopped / failed / missing)
  and their wall time, total and per run.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from .design import Case, load_campaign
from .driver import _open_db, _state

#: (key, label, log axis) of the parameters the design spans
AXES = (("E_over_sigma_y", "E/σY", True), ("K_over_sigma_y", "K/σY", False), ("n", "n", False),
        ("R2_over_R1", "R2/R1", True), ("nu", "ν", False))
PLANES = ((0, 1), (0, 2), (0, 3), (1, 2))
MARKERS = {"flat": "o", "rigid_sphere": "^", "two_body": "s"}


def point(case: Case) -> dict:
    """The design coordinates of one case (R2/R1 = inf on a flat; n = nan without hardening)."""
    p = case.params
    r2 = {"flat": math.inf, "rigid_sphere": p.get("indenter_radius"), "two_body": p.get("radius2")}
    K = p["K_over_sigma_y"]
    return {"E_over_sigma_y": p["E_over_sigma_y"], "K_over_sigma_y": K,
            "n": p["n"] if K > 0 else math.nan, "R2_over_R1": r2[case.scene], "nu": p["nu"],
            "curve": p.get("flow_curve") or ("voce" if p.get("Q_over_sigma_y", 0) > 0 else "ludwik")}


def table(cases: list[Case], db) -> dict:
    """Runs, states and wall times per set and scene; parameter ranges per set."""
    out: dict = {"sets": {}, "ranges": {}}
    for c in cases:
        row = out["sets"].setdefault(c.set, {}).setdefault(c.scene, {
            "runs": 0, "converged": 0, "stopped": 0, "failed": 0, "missing": 0, "wall_s": 0.0})
        state = _state(db, c.key)
        row["runs"] += 1
        row[state if state in row else "missing"] += 1
        if db is not None and state in ("converged", "stopped"):
            row["wall_s"] += float(db.record(c.key).wall_s)
        pt = point(c)
        rng = out["ranges"].setdefault(c.set, {})
        for key, _, _ in AXES:
            x = pt[key]
            if np.isfinite(x):
                lo, hi = rng.get(key, (math.inf, -math.inf))
                rng[key] = (min(lo, x), max(hi, x))
    return out


def write_markdown(path: Path, info: dict, source: str) -> None:
    lines = [f"# Campaign design: `{source}`", "",
             "| set | scene | runs | converged | stopped | failed | missing | wall total (h) | per run (s) |",
             "|---|---|---|---|---|---|---|---|---|"]
    for s, scenes in info["sets"].items():
        for scene, r in scenes.items():
            done = r["converged"] + r["stopped"]
            per = f"{r['wall_s'] / done:.0f}" if done else "—"
            lines.append(f"| {s} | {scene} | {r['runs']} | {r['converged']} | {r['stopped']} | "
                         f"{r['failed']} | {r['missing']} | {r['wall_s'] / 3600:.2f} | {per} |")
    lines += ["", "| set | " + " | ".join(lab for _, lab, _ in AXES) + " |",
              "|---|" + "---|" * len(AXES)]
    for s, rng in info["ranges"].items():
        cells = [f"{rng[k][0]:.3g} – {rng[k][1]:.3g}" if k in rng else "—" for k, _, _ in AXES]
        lines.append(f"| {s} | " + " | ".join(cells) + " |")
    if info.get("replaced"):
        lines += ["", "## Replaced cases", "",
                  "Cases the FE could not finish as designed, replaced in the campaign's `[replace]` "
                  "table (the designed run stays out of calibration and validation).", "",
                  "| set | designed case | replaced by | h_max (of the smaller radius) | state | reason |",
                  "|---|---|---|---|---|---|"]
        lines += [f"| {r['set']} | {r['designed']} | {r['name']} | {r['h_max']:g} | {r['state']} | "
                  f"{r['reason']} |" for r in info["replaced"]]
    lines += ["", "![design](design.png)", ""]
    path.write_text("\n".join(lines))


def plot(path: Path, cases: list[Case]) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(10, 8.5))
    colours = {"calibration": "tab:blue", "validation": "tab:red"}
    pts = [(c, point(c)) for c in cases]
    for ax, (i, j) in zip(axes.ravel(), PLANES, strict=True):
        kx, lx, logx = AXES[i]
        ky, ly, logy = AXES[j]
        for s in colours:
            for scene, m in MARKERS.items():
                sel = [p for c, p in pts if c.set == s and c.scene == scene
                       and np.isfinite(p[kx]) and np.isfinite(p[ky])]
                if sel:
                    ax.scatter([p[kx] for p in sel], [p[ky] for p in sel], marker=m,
                               facecolors="none" if s == "validation" else colours[s],
                               edgecolors=colours[s], s=36, label=f"{s}, {scene}")
        ax.set_xscale("log" if logx else "linear")
        ax.set_yscale("log" if logy else "linear")
        ax.set_xlabel(lx)
        ax.set_ylabel(ly)
        ax.grid(alpha=0.3)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    for ax in axes.ravel()[1:]:
        for h, lab in zip(*ax.get_legend_handles_labels(), strict=True):
            if lab not in labels:
                handles.append(h)
                labels.append(lab)
    fig.legend(handles, labels, loc="lower center", ncol=3, fontsize=8)
    fig.suptitle("Campaign design (filled: calibration, open: validation; "
                 "n shown where K > 0, R2/R1 for spheres)", fontsize=10)
    fig.tight_layout(rect=(0, 0.08, 1, 0.97))
    fig.savefig(path, dpi=110)
    plt.close(fig)


def write_design(campaign_path, db_path, out) -> list[Case]:
    """Write ``design.md``, ``design.json`` and ``design.png`` of the campaign file ``campaign_path``
    (the runs' state read from the database at ``db_path``, absent: all missing) into ``out``;
    returns the campaign's cases."""
    campaign = load_campaign(campaign_path)
    cases = list(campaign.cases)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    db = _open_db(Path(db_path))
    info = table(cases, db)
    info["points"] = [{"set": c.set, "scene": c.scene, "name": c.name, **point(c)} for c in cases]
    info["replaced"] = [{"set": c.set, "designed": c.replaces[0], "name": c.name, "reason": c.replaces[1],
                         "h_max": c.params["h_max"], "state": _state(db, c.key)}
                        for c in cases if c.replaces]
    (out / "design.json").write_text(json.dumps(info, indent=1, default=float) + "\n")
    write_markdown(out / "design.md", info, str(campaign_path))
    plot(out / "design.png", cases)
    return cases
