# Two entry points (README): `make reproduce-all` and `make test`.
# Both first make sure .venv matches environment.lock (hash-checked install).
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed-from-lock
# workflow rules call `python` and `infsup-contact`: they must resolve to the venv
export PATH := $(CURDIR)/$(BIN):$(PATH)

.PHONY: reproduce-all test env clean-env producers-kratos

env: $(STAMP)

# Rebuilt when missing or older than the lock (or pyproject.toml).
$(STAMP): environment.lock pyproject.toml
	@$(PYTHON) -c 'import sys; sys.exit(sys.version_info[:2] != (3, 11))' || \
	  { echo "error: Python 3.11 is required (found $$($(PYTHON) --version 2>&1)); set PYTHON=python3.11"; exit 1; }
	@$(PYTHON) -c 'import ensurepip' 2>/dev/null || \
	  { [ "$$(id -u)" = 0 ] && apt-get update -qq && apt-get install -y -qq python3-venv; } || \
	  { echo "error: the Python venv module is missing: install the Debian package python3-venv"; exit 1; }
	rm -rf $(VENV)
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --require-hashes -r environment.lock
	$(BIN)/pip install --quiet --no-deps -e .
	touch $(STAMP)

reproduce-all: $(STAMP)
	bash workflow/scripts/ensure_tex.sh
	$(BIN)/snakemake reproduce-all

test: $(STAMP)
	OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 $(BIN)/python -m pytest -n 2

# Optional producer (examples/producers/kratos): Kratos Multiphysics 10.4.4 into .venv, hash-checked
# (environment-producers.lock pins numpy to environment.lock's, so the suite's stack is unchanged).
producers-kratos: $(VENV)/.producers-kratos

$(VENV)/.producers-kratos: environment-producers.lock $(STAMP)
	$(BIN)/pip install --quiet --require-hashes -r environment-producers.lock
	touch $@

clean-env:
	rm -rf $(VENV)
