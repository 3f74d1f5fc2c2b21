# Every target does its own set-up on a fresh machine: the venv is created and the
# package installed (with its test and docs extras, its C module compiled) when missing or
# when pyproject.toml, setup.py or a C source changed.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test lint docs bench clean system mutation

# Debian packages the tests exercise for real: headless Chromium opens the HTML report,
# gcc compiles the C export and hrgtc's own C module (setup.py). Installed with apt-get
# when missing (CI runs as root).
SYSTEM_COMMANDS := chromium gcc

# setup.py compiles the C sources (NATIVE) in place: gcc must be there first (system).
NATIVE := src/hrgtc/evaluation/_allan_octave.c src/hrgtc/_buffers.h \
  src/hrgtc/recording/_spike_native.c src/hrgtc/drift/_rate_native.c \
  src/hrgtc/thermometry/_plateau_native.c src/hrgtc/drift/_extended_native.c \
  $(wildcard src/hrgtc/recording/_motion_*.[ch])

$(STAMP): pyproject.toml setup.py $(NATIVE) | system
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test,docs]'
	touch $(STAMP)

demo: $(STAMP)
	$(BIN)/hrgtc demo -o demo-out --force

system:
	@missing=""; for c in $(SYSTEM_COMMANDS); do command -v $$c >/dev/null || missing="$$missing $$c"; done; \
	if [ -n "$$missing" ]; then \
	  echo "installing Debian packages:$$missing"; \
	  apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $$missing >/dev/null; \
	fi

test: $(STAMP) system
	$(BIN)/ruff check .
	PYTHONPATH=src $(BIN)/lint-imports --no-logo
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict --quiet
	$(BIN)/python -m pytest -n 2 -q

lint: $(STAMP)
	$(BIN)/ruff check .
	PYTHONPATH=src $(BIN)/lint-imports --no-logo

# The documentation site into build/site/ (strict: a broken link or a missing page fails).
docs: $(STAMP)
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict

# Mutation testing of recording/, compensate/, export/, model_fit.py and files.py (pyproject's
# [tool.mutmut]); not run by CI: the full set takes hours on 2 cores. MUTANTS narrows it, e.g.
# make mutation MUTANTS='hrgtc.core.files.*' (JOBS: parallel mutants, default 2)
MUTANTS ?=
JOBS ?= 2
mutation: $(STAMP)
	$(BIN)/python -m pip install --quiet 'mutmut==3.8.1'
	$(BIN)/mutmut run --max-children $(JOBS) $(MUTANTS)
	$(BIN)/mutmut results

bench: $(STAMP)
	$(BIN)/python bench/run.py

clean:
	rm -rf $(VENV) build dist site src/*.egg-info .pytest_cache .ruff_cache
	find src -name '*.so' -delete
