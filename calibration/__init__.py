"""Calibration of H̄(Λ), c²(Λ) and the large-deformation terms from FE (docs/design.md §2).

``spherecontact calibrate --db data/reference_v2.h5 --out model/coefficients.json
--report reports/calibration`` (``make calibrate``); ``calibration/README.md``.
"""

import os as _os

# The fits are small dense problems (hundreds of rows, ~20 columns): BLAS threads only
# add overhead and contend with other jobs on the machine. Effective when this package
# is imported before numpy (the command line) and the variables are unset; the Makefile
# sets the same variables. Whatever they say, ``pipeline.calibrate_runs`` runs with one
# BLAS thread (``threads.py``): the written file must not depend on them.
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    _os.environ.setdefault(_var, "1")
