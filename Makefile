# Two commands set everything up on a fresh machine (Python >= 3.10 with venv):
#   make validate   the validation suite on the default scenes (writes validation-report/)
#   make test       the test suite
# Both create .venv in this directory and install the package with every backend into it.

PYTHON ?= python3
VENV := .venv
STAMP := $(VENV)/.installed

.PHONY: validate test clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(VENV)/bin/python -m pip install --quiet --upgrade pip
	$(VENV)/bin/python -m pip install --quiet -e '.[all]'
	touch $(STAMP)

validate: $(STAMP)
	$(VENV)/bin/signorini validate

test: $(STAMP)
	$(VENV)/bin/python -m pytest

clean:
	rm -rf $(VENV) validation-report
