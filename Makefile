# Two commands from a fresh clone (Python 3.11+ is all they need):
#   make train   set up .venv with cartpole-q alone and train the embedded default config
#   make test    add the development tools to .venv and run the whole test suite
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
# One stamp per install: the base package (what `make train` needs), the dev extra (tests
# and linters), the docs extra (the site). Each is installed once, when first needed.
BASE_STAMP := $(VENV)/.installed-base
DEV_STAMP := $(VENV)/.installed-dev
DOCS_STAMP := $(VENV)/.installed-docs

.PHONY: train test lint docs bench clean

# pip shows what it does (no --quiet): a first install takes a while, and says so first.
$(BASE_STAMP): pyproject.toml
	@echo "setting up $(VENV): installing cartpole-q and its dependencies (numpy, numba, gymnasium, matplotlib, typer, rich, pyyaml): about a minute"
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -e .
	@touch $@

# The dev extra is large (Ray, Optuna and TensorBoard for their tests; pytest, ruff, mypy):
# only `make test`, `make lint` and `make bench` install it.
$(DEV_STAMP): $(BASE_STAMP)
	@echo "installing the development tools into $(VENV) (pytest, hypothesis, ruff, mypy, import-linter; Ray, Optuna, TensorBoard for their tests): a few minutes"
	$(BIN)/python -m pip install -e ".[dev]"
	@touch $@

# The site's tools are an extra of their own (mkdocs, Material, mkdocstrings).
$(DOCS_STAMP): $(BASE_STAMP)
	@echo "installing the documentation tools into $(VENV) (mkdocs, Material, mkdocstrings)"
	$(BIN)/python -m pip install -e ".[docs]"
	@touch $@

train: $(BASE_STAMP)
	$(BIN)/cartpole-q train

test: $(DEV_STAMP)
	$(BIN)/python -m pytest -n 2 --dist loadgroup

lint: $(DEV_STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	$(BIN)/mypy
	$(BIN)/lint-imports

# The documentation site into site/; --strict: a broken link or reference fails the build.
docs: $(DOCS_STAMP)
	$(BIN)/mkdocs build --strict

bench: $(DEV_STAMP)
	$(BIN)/python benchmarks/throughput.py

clean:
	rm -rf $(VENV) .pytest_cache .mypy_cache .ruff_cache .hypothesis site
