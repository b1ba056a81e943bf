# Skinlab: `make demo` and `make test` do all set-up on a fresh machine.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.skinlab-installed
SIZE   ?= 640x640

.PHONY: demo test lint format setup sysdeps bench clean

setup: $(STAMP)

sysdeps:
	@bash tools/sysdeps.sh

$(STAMP): pyproject.toml tools/sysdeps.sh
	@bash tools/sysdeps.sh
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -e '.[dev,truth]'
	@touch $(STAMP)

demo: $(STAMP)
	$(VENV)/bin/skinlab demo --out out --size $(SIZE)

test: $(STAMP)
	$(VENV)/bin/ruff check .
	$(VENV)/bin/ruff format --check .
	$(PY) -m pytest -q

lint: $(STAMP)
	$(VENV)/bin/ruff check .
	$(VENV)/bin/ruff format --check .

format: $(STAMP)
	$(VENV)/bin/ruff check --fix .
	$(VENV)/bin/ruff format .

bench: $(STAMP)
	$(VENV)/bin/skinlab bench peer

clean:
	rm -rf out .pytest_cache
