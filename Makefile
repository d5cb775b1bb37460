# Two commands for a new user: `make demo` and `make test` (both set up .venv on first use).
VENV := .venv
STAMP := $(VENV)/.installed
PYTEST_ARGS ?= --durations=25  # the slowest tests printed: where the suite's time goes (issue 27)
# two pytest-xdist workers (`--dist worksteal`: each takes one half of the tests in file order, the longest files
# first, and steals from the other's end when idle, so a file's module fixtures are computed once unless the two
# halves meet in it), the MPI tests one at a time (a lock; tests/conftest.py); PYTEST_WORKERS=0: one process.
# Clean-clone runs, 2026-11-29: 568 s of pytest with worksteal against 675 s with loadfile
# (benchmarks/results/suite_time.md)
PYTEST_WORKERS ?= 2

.PHONY: demo test lint docs setup clean clean-numba

$(STAMP): pyproject.toml tools/setup_venv.sh
	bash tools/setup_venv.sh

setup: $(STAMP)

demo: $(STAMP)
	$(VENV)/bin/wheelrail demo

# PYTHONDONTWRITEBYTECODE emptied: an environment that sets it (this project's development machines do) makes every
# process compile our modules from source and pytest rewrite every test file's asserts again (collection 15 s CPU
# per worker instead of 6 s); the bytecode goes to the __pycache__ folders git ignores
test: $(STAMP)
	PYTHONDONTWRITEBYTECODE= $(VENV)/bin/python -m pytest -q -n $(PYTEST_WORKERS) --dist worksteal $(PYTEST_ARGS)

lint: $(STAMP)
	$(VENV)/bin/ruff check . && $(VENV)/bin/ruff format --check .

# the documentation site in docs/_build/html (warnings are errors; tests/test_docs.py builds it in `make test`)
docs: $(STAMP)
	$(VENV)/bin/python -m sphinx -b html -W --keep-going docs docs/_build/html

clean:
	rm -rf $(VENV) out .pytest_cache

# numba's on-disk cache is keyed on each function's own file: after editing a jitted function that another
# module's cached function calls (e.g. the FASTSIM kernel inside the compiled RK4 loop), drop the cache
clean-numba:
	find rigid_dynamics -name '*.nbi' -delete -o -name '*.nbc' -delete
