# Two commands set everything up on a fresh machine (Python >= 3.10 with venv):
#   make validate   the validation suite on the default scenes (writes validation-report/)
#   make test       the test suite
# Both create .venv in this directory and install the package with every backend into it.

PYTHON ?= python3
VENV := .venv
STAMP := $(VENV)/.installed

.PHONY: validate test clean

$(STAMP): pyproject.toml tools/install_petsc.sh
	$(PYTHON) -m venv $(VENV)
	$(VENV)/bin/python -m pip install --quiet --upgrade pip
	$(VENV)/bin/python -m pip install --quiet -e '.[all]'
	@# Debian packages, installed with apt when we are root on Debian: SuiteSparse's headers for
	@# CHOLMOD, the fastest factorisation here (without them SciPy's SuperLU is used), and chromium
	@# for tests/test_explore.py, which drives the explorer in a browser (it skips without one).
	@missing=""; [ -e /usr/include/suitesparse/cholmod.h ] || missing="libsuitesparse-dev"; \
	  [ -e /usr/bin/chromium ] || missing="$$missing chromium"; \
	  if [ -n "$$missing" ] && command -v apt-get >/dev/null 2>&1 && [ "$$(id -u)" = 0 ]; then \
	  (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq \
	    $$missing >/dev/null) || echo "make: $$missing not installed"; fi
	@$(VENV)/bin/python -m pip install --quiet -e '.[fast]' \
	  || echo "make: CHOLMOD (scikit-sparse) not installed; SuperLU will be used"
	@# the petsc methods (SNES-VI, TAO under MPI): Debian's PETSc + petsc4py built against it
	@sh tools/install_petsc.sh $(VENV)
	touch $(STAMP)

validate: $(STAMP)
	$(VENV)/bin/signorini validate

test: $(STAMP)
	$(VENV)/bin/python -m pytest

clean:
	rm -rf $(VENV) validation-report
