"""The FE campaign: its design (``design.py``, a TOML file expanded to cases), the driver that runs
it into the reference database (``driver.py``), the design report (``report.py``) and the
increment-converged first loadings of a set stored as data (``increments.py``); command line
``spherecontact campaign run|design|increments`` (``cli.py``)."""
