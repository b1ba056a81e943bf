# Skinlab: `make demo` and `make test` do all set-up on a fresh machine.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.skinlab-installed
# Blender (pyproject's [peers] extra) in an environment of its own: bpy 5.0 pins numpy < 2, Skinlab's
# has numpy 2; Skinlab runs it in a child process (skinlab/bench/blender_peer.py). `make test` and
# `make bench` install it, `make demo` does not; where it cannot be installed they say so and go on.
BLENDER_VENV  := .venv-blender
BLENDER_STAMP := $(BLENDER_VENV)/.skinlab-peers
SIZE   ?= 640x640

.PHONY: demo test lint format setup sysdeps bench clean peers

setup: $(STAMP)

sysdeps:
	@bash tools/sysdeps.sh

$(STAMP): pyproject.toml tools/sysdeps.sh
	@bash tools/sysdeps.sh
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -e '.[dev,truth]'
	@touch $(STAMP)

peers: $(BLENDER_STAMP)

$(BLENDER_STAMP): pyproject.toml | $(STAMP)
	@if $(PYTHON) -c 'import sys; sys.exit(sys.version_info[:2] != (3, 11))'; then \
	  (test -x $(BLENDER_VENV)/bin/python || $(PYTHON) -m venv $(BLENDER_VENV)) \
	  && $(PY) -c "import tomllib; print('\n'.join(tomllib.load(open('pyproject.toml', 'rb'))['project']['optional-dependencies']['peers']))" > $(BLENDER_VENV)/peers.txt \
	  && $(BLENDER_VENV)/bin/python -m pip install -q -r $(BLENDER_VENV)/peers.txt && touch $@ \
	  || echo "Blender peers (pyproject's [peers]) could not be installed into $(BLENDER_VENV): their tests are skipped"; \
	else echo "Blender peers (pyproject's [peers], bpy 5.0.1) need CPython 3.11, $(PYTHON) is $$($(PYTHON) -V 2>&1): their tests are skipped"; fi

demo: $(STAMP)
	$(VENV)/bin/skinlab demo --out out --size $(SIZE)

test: $(STAMP) $(BLENDER_STAMP)
	$(VENV)/bin/ruff check .
	$(VENV)/bin/ruff format --check .
	$(VENV)/bin/mypy
	$(PY) -m pytest -q

lint: $(STAMP)
	$(VENV)/bin/ruff check .
	$(VENV)/bin/ruff format --check .
	$(VENV)/bin/mypy

format: $(STAMP)
	$(VENV)/bin/ruff check --fix .
	$(VENV)/bin/ruff format .

bench: $(STAMP) $(BLENDER_STAMP)
	$(VENV)/bin/skinlab bench peer

clean:
	rm -rf out .pytest_cache
