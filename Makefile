# Two commands do all the set-up on a fresh machine:
#   make demo   -- creates .venv, builds and installs thermofriction, runs the main job
#   make test   -- the same with the test extras, then the whole test suite (C core included)
PYTHON ?= python3
VENV   ?= .venv
BIN     = $(VENV)/bin
SOURCES = $(shell find core src -type f -not -name '*.pyc') pyproject.toml CMakeLists.txt

.PHONY: demo test install bench clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

$(VENV)/.installed: $(BIN)/python $(SOURCES)
	$(BIN)/python -m pip install --quiet '.[test]'
	touch $@

install: $(VENV)/.installed

demo: install
	$(BIN)/thermofriction demo

test: install
	$(BIN)/python -m pytest -q

bench: install
	$(BIN)/python benchmarks/bench_simulate.py

clean:
	rm -rf $(VENV) build
