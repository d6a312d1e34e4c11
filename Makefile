# Two entry points (README): `make reproduce-all` and `make test`.
# Both first make sure .venv matches environment.lock (hash-checked install).
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed-from-lock
# workflow rules call `python` and `infsup-contact`: they must resolve to the venv
export PATH := $(CURDIR)/$(BIN):$(PATH)

.PHONY: reproduce-all test env clean-env producers-kratos producers-dolfinx producers-getfem producers-freefem producers-ngsolve producers-calculix

env: $(STAMP)

# Rebuilt when missing or older than the lock (or pyproject.toml).
$(STAMP): environment.lock pyproject.toml
	@$(PYTHON) -c 'import sys; sys.exit(sys.version_info[:2] != (3, 11))' || \
	  { echo "error: Python 3.11 is required (found $$($(PYTHON) --version 2>&1)); set PYTHON=python3.11"; exit 1; }
	@$(PYTHON) -c 'import ensurepip' 2>/dev/null || \
	  { [ "$$(id -u)" = 0 ] && apt-get update -qq && apt-get install -y -qq python3-venv; } || \
	  { echo "error: the Python venv module is missing: install the Debian package python3-venv"; exit 1; }
	@echo "make env: [1/4] a fresh $(VENV) with $$($(PYTHON) --version 2>&1) (the old one removed)"
	rm -rf $(VENV)
	$(PYTHON) -m venv $(VENV)
	@echo "make env: [2/4] $$(grep -c '^[a-zA-Z0-9]' environment.lock) pinned packages from environment.lock, hash-checked (a few minutes with an empty pip cache; pip's own progress on a terminal)"
	$(BIN)/pip install $$([ -t 1 ] || echo --quiet) --require-hashes -r environment.lock
	@echo "make env: [3/4] infsup-contact itself, editable (src/)"
	$(BIN)/pip install --quiet --no-deps -e .
	@echo "make env: [4/4] done: $(VENV) matches environment.lock ($(STAMP))"
	touch $(STAMP)

# Also installs the Kratos producer (a hashed pip lock, like the suite's); if that fails (no network,
# no wheel for this platform) the run goes on and Kratos' claims are NOT RUN in the ledger. DOLFINx
# and GetFEM stay separate installs (make producers-dolfinx, make producers-getfem): a code not
# installed is a "not installed" row and NOT RUN claims, and a later install reruns the stage.
reproduce-all: $(STAMP)
	bash workflow/scripts/ensure_tex.sh
	@$(MAKE) --no-print-directory producers-kratos || \
	  echo "make reproduce-all: installing the Kratos producer failed (above); going on without it: its claims are NOT RUN (retry: make producers-kratos)"
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

# Foreign producers (examples/producers/): each code in its own interpreter, not in .venv.
# DOLFINx wheels need Python >= 3.12; the lock pins them with their hashes.
# (the first candidate that runs: a pyenv shim exists but fails where 3.12 is not selected)
PYTHON312 ?= $(shell for p in python3.12 python3.13 $(wildcard $(HOME)/.pyenv/versions/3.1[2-9]*/bin/python); do \
  $$p -c 'import sys; sys.exit(sys.version_info[:2] < (3, 12))' 2>/dev/null && { command -v $$p; break; }; done)
DOLFINX_VENV  := .venv-dolfinx
DOLFINX_STAMP := $(DOLFINX_VENV)/.installed-from-lock

producers-dolfinx: $(DOLFINX_STAMP)

$(DOLFINX_STAMP): examples/producers/dolfinx/requirements.lock
	@[ -n "$(PYTHON312)" ] && $(PYTHON312) -c 'import sys; sys.exit(sys.version_info[:2] < (3, 12))' || \
	  { echo "error: DOLFINx 0.11 wheels need Python >= 3.12 (found '$(PYTHON312)'); set PYTHON312=/path/to/python3.12"; exit 1; }
	rm -rf $(DOLFINX_VENV)
	$(PYTHON312) -m venv $(DOLFINX_VENV)
	$(DOLFINX_VENV)/bin/pip install --quiet --require-hashes -r examples/producers/dolfinx/requirements.lock
	touch $@

# GetFEM from Debian (python3-getfem 5.4 for the system /usr/bin/python3): needs root.
producers-getfem:
	@/usr/bin/python3 -c 'import getfem, scipy, yaml' 2>/dev/null || \
	  { [ "$$(id -u)" = 0 ] && apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq \
	      --no-install-recommends python3-getfem python3-scipy python3-yaml >/dev/null; } || \
	  { echo "error: GetFEM is installed from Debian as root: apt-get install python3-getfem python3-scipy python3-yaml"; exit 1; }
	@/usr/bin/python3 -c 'import getfem; print("GetFEM", getfem.getfem_env("release"), "for /usr/bin/python3")'

# FreeFEM from Debian (freefem++ 4.11: the binary; libfreefem++: its plugins, `load "msh3"`;
# freefem++-doc: the shipped tutorial examples/tutorial/mortar-DN-4.edp the producer exports): needs root.
# The exporter runs in .venv (FreeFEM is no Python package) and sets FF_LOADPATH=/usr/lib/freefem++:
# Debian's /etc/freefem++.pref names /usr/lib/ff++/4.9/lib, which no package creates.
FREEFEM_TUTORIAL := /usr/share/doc/freefem++/examples/tutorial/mortar-DN-4.edp
producers-freefem:
	@{ command -v FreeFem++ >/dev/null && [ -f /usr/lib/freefem++/msh3.so ] && [ -f $(FREEFEM_TUTORIAL) ]; } 2>/dev/null || \
	  { [ "$$(id -u)" = 0 ] && apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq \
	      --no-install-recommends freefem++ libfreefem++ freefem++-doc >/dev/null; } || \
	  { echo "error: FreeFEM is installed from Debian as root: apt-get install freefem++ libfreefem++ freefem++-doc"; exit 1; }
	@echo "FreeFEM $$(FreeFem++ 2>&1 | sed -n 's/^FreeFem++ - version \([^ ]*\).*/\1/p') (Debian freefem++ $$(dpkg-query -W -f '$${Version}' freefem++)), tutorial $(FREEFEM_TUTORIAL)"

# NGSolve is a dependency of the suite itself (environment.lock): its producer runs in .venv and
# installs nothing; this target only checks that .venv's NGSolve imports (no prerequisite: it never
# rebuilds .venv; if the check fails, run make env).
producers-ngsolve:
	@$(BIN)/python -c 'import ngsolve, scipy, yaml; print("NGSolve", ngsolve.__version__, "in $(VENV)")' 2>/dev/null || \
	  { echo "error: NGSolve does not import in $(VENV): it is one of the suite's own dependencies, run make env"; exit 1; }

# CalculiX ccx 2.20 from Debian's source package, built with our dump of its mortar coupling
# (examples/producers/calculix/install.sh: deb-src, build-dep, apt-get source, insert, make; needs
# root, ~2 min on 2 cores). The fetched source and the binary stay in .calculix/ (git-ignored).
producers-calculix:
	bash examples/producers/calculix/install.sh
