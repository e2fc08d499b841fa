"""Validation of the closed-form model and peer laws against FE runs (docs/design.md §5).

``python -m spherecontact.validation`` (``make validate``) writes the report
``reports/validation/index.md``. Modules, in pipeline order:

* :mod:`.peers` — the published laws, written from their papers;
* :mod:`.cases` — a database run as a validation case and the sphere pair it stands for;
* :mod:`.peer_scenes` — where each peer law applies to a case and with which E*, R*, yield;
* :mod:`.mdr` — LAMMPS' ``mdr`` law on a case, from the curves LAMMPS computed
  (``data/peers/mdr.json``); :mod:`.lammps_mdr` drives LAMMPS to make them (optional extra
  ``lammps``, ``make peers-mdr``); :mod:`.mdr_report` — its report section;
* :mod:`.metrics` — relative errors, max and RMS over windows, pooling;
* :mod:`.compare` — the model and the peers on one run, per window and per level;
* :mod:`.tables`, :mod:`.charts` — Markdown tables and matplotlib charts;
* :mod:`.studies` — FE accuracy studies and the speed–accuracy chart;
* :mod:`.stability` — locking, penalty contact, oversized increments, extreme h/R, the
  model outside its calibrated range;
* :mod:`.config` — thresholds (``validation/thresholds.toml``); :mod:`.report` — the report.
"""
