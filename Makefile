# Two commands do all the set-up on a fresh Debian/Ubuntu machine:
#   make run    set up, then run the main job
#   make test   set up, then run the test suite
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: run test setup clean

$(STAMP): pyproject.toml scripts/system-deps.txt
	@scripts/install-system-deps
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	@$(PY) -m pip install -q --upgrade pip
	@$(PY) -m pip install -q -e '.[test]'
	@touch $(STAMP)

setup: $(STAMP)

run: $(STAMP)
	$(VENV)/bin/studyapp compile
	$(VENV)/bin/studyapp gui

# the numba kernels compiled once, before any test process needs them (studyapp compile); then the
# suite on every core (at most 4), each worker with its own JACK server, Xvfb display and temporary
# directory (a worker that runs out of tests takes some of another's: worksteal); then the tests that
# measure a real-time guarantee (marker "alone"), with the machine to themselves
test: $(STAMP)
	$(VENV)/bin/studyapp compile
	$(PY) -m pytest -q -n auto --maxprocesses 4 --dist worksteal -m "not alone"
	$(PY) -m pytest -q -m alone

clean:
	rm -rf $(VENV) build *.egg-info
