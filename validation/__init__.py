"""Validation of the closed-form model and peer laws against FE runs (docs/design.md §5).

``spherecontact validate`` (``make validate``, :mod:`.cli`) writes the report
``reports/validation/index.md``. The published peer laws are :mod:`spherecontact.peers`, the curve
metrics :mod:`spherecontact.metrics` (the low layer). Modules, in pipeline order:

* :mod:`.cases` — a database run as a validation case and the sphere pair it stands for;
* :mod:`.peer_scenes` — where each peer law applies to a case and with which E*, R*, yield;
* :mod:`.mdr` — LAMMPS' ``mdr`` law on a case, from the curves LAMMPS computed
  (``data/peers/mdr.json``); :mod:`.lammps_mdr` drives LAMMPS to make them (optional extra
  ``lammps``, ``spherecontact peers mdr``); :mod:`.mdr_report` — its report section;
* :mod:`.compare` — the model and the peers on one run, per window and per level;
* :mod:`.tables`, :mod:`.charts` — Markdown tables and matplotlib charts;
* :mod:`.studies` — FE accuracy studies and the speed–accuracy chart (:mod:`.study_runs` reads
  the study runs on disk);
* :mod:`.stability` — locking, penalty contact, oversized increments, extreme h/R, the
  model outside its calibrated range;
* :mod:`.increments_report` — the model against the increment-converged first loadings
  (``data/increments_v2.json``);
* :mod:`.config` — thresholds (``validation/thresholds.toml``); :mod:`.report` — the report.
"""
