# fivebar: one-command set-up, tests, reproduction of both papers, benchmarks.
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed-stamp

.PHONY: install venv-and-browser browser bytecode test reproduce golden bench clean

# The browser (apt-get: a download of about 100 MB on a fresh machine) and the venv (pip) are
# installed side by side, then fivebar's bytecode compiled: on a fresh machine the slower of the two,
# not their sum (about half a minute less for CI).
install:
	@$(MAKE) --no-print-directory -j2 venv-and-browser
	@$(MAKE) --no-print-directory bytecode

venv-and-browser: $(STAMP) browser
	@:

# Debian's chromium for the browser tests of `fivebar view` (tests/test_view.py): installed where it
# is missing and apt-get is available (CI runs as root on a fresh machine); elsewhere `make install`
# still succeeds, and those tests skip (or fail when CI is set).
browser:
	@command -v chromium >/dev/null 2>&1 || command -v chromium-browser >/dev/null 2>&1 || \
	  (command -v apt-get >/dev/null 2>&1 && export DEBIAN_FRONTEND=noninteractive && \
	    (apt-get install -y -q chromium || (apt-get update -q && apt-get install -y -q chromium))) || \
	  echo "note: chromium is not installed: the browser tests of fivebar view will skip (and fail when CI is set)"

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet -e '.[test]'
	touch $(STAMP)

# fivebar's own bytecode, as a regular (not editable) install compiles it: where PYTHONDONTWRITEBYTECODE
# is set (as in this project's machines' environment, which CI runs in) no process writes it, so each
# one (every subprocess of the tests, a fresh `fivebar`) compiled the modules it imports again: `fivebar
# aspects configs/m1.yaml --depth 4` took 1.74-1.99 s with fivebar's bytecode, 2.06-2.70 s without.
# Only what changed since the last run is compiled again (a fraction of a second when nothing did).
bytecode: $(STAMP)
	@$(BIN)/python -m compileall -q fivebar_cli

test: install
	$(BIN)/python -m pytest

reproduce: install
	$(BIN)/fivebar reproduce

golden: install   # regenerate the reference outputs the tests compare against (after an intended change)
	$(BIN)/fivebar reproduce -o tests/golden --no-plot --quiet
	# the golden files are the .qt and CSV files: not the runs' manifests or the GeoJSON beside them
	# (tests read tests/golden/M1 as an output folder, which a manifest would change)
	find tests/golden -name .fivebar -type d -prune -exec rm -rf {} +
	find tests/golden -name '*.geojson' -delete

bench: install
	$(BIN)/python benchmarks/run_all.py

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache .hypothesis
