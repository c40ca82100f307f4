# The two commands: `make demo` (the main job) and `make test` (the suite).
# Both create .venv with the machine's python3 when it is missing and install tumble into it.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-dev
BENCH_STAMP := $(VENV)/.installed-bench
DEMO ?= t-handle
RUN_DIR ?= runs/$(DEMO)

.PHONY: demo test portability truth browser bench report lint format clean clean-cache docs

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip

$(STAMP): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install -q -e ".[dev]"
	touch $@

$(BENCH_STAMP): pyproject.toml $(STAMP)
	$(BIN)/python -m pip install -q -e ".[dev,bench]"
	touch $@

# The demo's run compiles simulate's loop; numba compiles simulate_batch's on its first call
# (15 s on a shared 2-core machine), so the demo compiles it too: later first calls load it
# from numba's cache in about 2 s.
WARM_BATCH = import tumble; tumble.simulate_batch(tumble.RigidBody.from_mass_properties( \
	tumble.mass.t_handle()), 0.02, h=0.01, omega0=[[1.0, 0.05, 0.0]])

demo: $(STAMP)
	$(BIN)/tumble run $(DEMO) --out $(RUN_DIR) --force
	$(BIN)/python -c "$(WARM_BATCH)"

# tests/viz/test_viz_browser.py loads view.html in a real headless Chromium (Debian's packages).
# The suite runs on every core (pytest-xdist: JOBS=auto; JOBS=0 runs it in this process).
JOBS ?= auto
test: $(STAMP) browser
	$(BIN)/python -m pytest -n $(JOBS)

# The round-off-sensitive tests again, on arithmetic this CPU does not use by default, so that a
# tolerance that holds for one CPU only fails here and not on a user's machine: numba compiled
# for a generic x86-64 (no SIMD, no FMA: NUMBA_CPU_NAME=generic; its cache keys on the CPU name,
# so the host's kernels stay cached beside these) and numpy with every SIMD dispatch above its
# baseline turned off (the AVX2/FMA3 and AVX-512 kernels that numpy lists as dispatchable and
# finds on this CPU, in NPY_DISABLE_CPU_FEATURES), both in one run to keep CI's time.
# OpenBLAS's own variables (OPENBLAS_CORETYPE, ...) are left as the machine sets them.
PORTABILITY_TESTS ?= tests/ode tests/rigid/test_rigid_kernels.py tests/rigid/test_rigid_batch.py \
	tests/rigid/test_rigid_geometric.py tests/rigid/test_rigid_adaptive.py tests/rigid/test_rigid_separatrix.py \
	tests/structural/test_structural_compiled.py tests/test_exact.py tests/test_so3.py tests/truth
NPY_DISPATCHED = $(BIN)/python -c "from numpy._core import _multiarray_umath as m; \
	print(' '.join(f for f in m.__cpu_dispatch__ if m.__cpu_features__.get(f)))"

portability: $(STAMP)
	NUMBA_CPU_NAME=generic NPY_DISABLE_CPU_FEATURES="$$($(NPY_DISPATCHED))" \
		$(BIN)/python -m pytest -n $(JOBS) -p no:cacheprovider $(PORTABILITY_TESTS)

# The truth suite's nightly run: random bodies, spins, loads and steps, many examples each
# (`make test` runs a fixed, deterministic sample of the same tests).
truth: $(STAMP)
	HYPOTHESIS_PROFILE=thorough $(BIN)/python -m pytest -p no:cacheprovider tests/truth

browser:
	@command -v chromium >/dev/null && command -v chromedriver >/dev/null \
		|| (apt-get update -qq && DEBIAN_FRONTEND=noninteractive \
		apt-get install -y -q --no-install-recommends chromium chromium-driver)

# OpenSeesPy (the beam peer) imports only with Debian's BLAS/LAPACK; install them when we can.
bench: $(BENCH_STAMP)
	@dpkg -s libblas3 liblapack3 >/dev/null 2>&1 || (apt-get update -qq && apt-get install -y -q libblas3 liblapack3) \
		|| echo "note: libblas3/liblapack3 missing; the OpenSees columns will be skipped"
	OPENBLAS_NUM_THREADS=1 $(BIN)/python benchmarks/run_all.py

# The integrator report card (tumble report, about 5 minutes): every method of METHODS beside
# scipy and MuJoCo (the bench extra); docs/report.md is its report.md, with the machine noted.
report: $(BENCH_STAMP)
	OPENBLAS_NUM_THREADS=1 $(BIN)/tumble report --out runs/report
	cp runs/report/report.md docs/report.md

# The documentation site (Sphinx, docs/conf.py) in build/docs/html/index.html; warnings are errors.
docs: $(STAMP)
	$(BIN)/sphinx-build -W --keep-going -b html -d build/docs/doctrees docs build/docs/html

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	PYTHONPATH=src $(BIN)/lint-imports --no-cache
	$(BIN)/mypy

format: $(STAMP)
	$(BIN)/ruff format .
	$(BIN)/ruff check --fix .

clean:
	rm -rf $(VENV) runs .pytest_cache .ruff_cache .hypothesis

# numba caches a loop bound from a template (tumble/ode/templates.py) under the template's
# file, so editing a family's compiled step elsewhere does not invalidate it: drop the cache.
clean-cache:
	find src -path '*__pycache__*' \( -name '*.nbi' -o -name '*.nbc' \) -delete
