# fivebar: one-command set-up, tests, reproduction of both papers, benchmarks.
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed-stamp

.PHONY: install test reproduce golden bench clean

install: $(STAMP)

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet -e '.[test]'
	touch $(STAMP)

test: install
	$(BIN)/python -m pytest

reproduce: install
	$(BIN)/fivebar reproduce

golden: install   # regenerate the reference outputs the tests compare against (after an intended change)
	$(BIN)/fivebar reproduce -o tests/golden --no-plot --quiet

bench: install
	$(BIN)/python benchmarks/run_all.py

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache .hypothesis
