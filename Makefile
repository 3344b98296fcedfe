# vibroblock: `make run` (set-up + main job) and `make test` (set-up + tests) on a fresh machine.
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
# Compiled numba kernels are cached here, so tests, sweeps and FMU instances reuse them.
export NUMBA_CACHE_DIR := $(CURDIR)/.cache/numba
export MPLBACKEND := Agg

INSTALLED := $(VENV)/.installed
# One FMU per registered model variant (fmu_src/vibroblock/models) plus fmu_src's own
# FMU scripts: the build derives the list (build/build_fmus.py --list), so the stamp
# stands for all of them.  The build compiles every integrator's kernels once, one child
# process per core (build/kernels.py, kept in build/work/ for the tests); each Block FMU
# ships its default configuration's.
FMUS := build/fmus/.built
FMU_SOURCES := $(shell find fmu_src harness/ground/records -name '*.py' -o -name '*.npz') build/build_fmus.py build/status_shim.py build/fmi_status_shim.c \
	build/python_runtime.c build/python_runtime.h build/kernels.py build/documentation.py

.PHONY: setup fmus run test benchmark clean

setup: $(INSTALLED)

$(INSTALLED): requirements.txt pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -r requirements.txt
	$(PY) -m pip install --quiet --no-deps -e .
	touch $@

fmus: $(FMUS)

$(FMUS): $(INSTALLED) $(FMU_SOURCES)
	$(PY) build/build_fmus.py
	touch $@

run: fmus
	$(PY) -m harness.main

# pytest exits non-zero when no test ran (exit code 5), so an empty run fails here too.
# One worker per core (pytest-xdist), a test file's tests on one worker: most of a fresh
# run's time is numba compiling the kernels a file needs, once per worker.
test: fmus
	$(PY) -m pytest -q -n auto --dist loadfile

benchmark: fmus
	$(PY) -m harness.benchmarks.core_and_fmu
	$(PY) -m harness.benchmarks.fmi_boundary

clean:
	rm -rf build/fmus build/work .cache out
