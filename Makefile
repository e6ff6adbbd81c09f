# Two commands do all the set-up on a fresh machine:
#   make demo   -- creates .venv, builds and installs thermofriction, runs the main job
#   make test   -- the same with the test extras, then the whole test suite (C core included)
#   make docs   -- the documentation site into docs/_build/html (installs the docs extra into .venv)
PYTHON ?= python3
VENV   ?= .venv
BIN     = $(VENV)/bin
SOURCES = $(shell find core src -type f -not -name '*.pyc') pyproject.toml CMakeLists.txt

.PHONY: demo test install bench docs clean octave

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

# the docs extra's requirements only (read from pyproject.toml), without rebuilding the package
$(VENV)/.docs-installed: $(VENV)/.installed pyproject.toml
	$(BIN)/python -c "import tomllib; print(' '.join(tomllib.load(open('pyproject.toml', 'rb'))['project']['optional-dependencies']['docs']))" \
	  | xargs $(BIN)/python -m pip install --quiet
	touch $@

# HTML from the guides (docs/*.md), the API reference (docstrings) and the executed gallery (examples/gallery);
# every warning is an error
docs: $(VENV)/.docs-installed
	$(BIN)/python -m sphinx -b html -E -W --keep-going -q docs docs/_build/html
	@echo "docs: open docs/_build/html/index.html"

# the MATLAB/Octave MEX gateway (matlab/, docs/matlab.md), compiled by Octave's mkoctfile from the C sources
octave:
	octave-cli --no-gui --norc --eval "addpath('$(CURDIR)/matlab'); disp(thermofriction.build())"

bench: install
	$(BIN)/python benchmarks/bench_simulate.py

clean:
	rm -rf $(VENV) build docs/_build docs/api/generated docs/gallery docs/sg_execution_times.rst
