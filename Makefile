# Two commands do all the set-up on a fresh machine:
#   make demo   -- creates .venv, builds and installs thermofriction, runs the main job
#   make test   -- the same with the test extras, then the whole test suite (C core included)
#   make docs   -- the documentation site into docs/_build/html (installs the docs extra into .venv)
#   make dist   -- the wheel and the sdist into dist/ (python -m build; README.md, "Install with pip")
PYTHON ?= python3
VENV   ?= .venv
BIN     = $(VENV)/bin
SOURCES = $(shell find core src -type f -not -name '*.pyc') pyproject.toml CMakeLists.txt
# the cross compiler the package build uses for the FMU's win64 DLL when it is on PATH (docs/fmu.md#windows)
MINGW  ?= x86_64-w64-mingw32-gcc

.PHONY: demo test install bench docs dist clean octave FORCE

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

# which compilers the build finds, rewritten only when that changes (installing MinGW-w64 after a first
# `make install` then rebuilds the package, with the DLL)
$(VENV)/.compilers: FORCE
	@mkdir -p $(VENV); found="$$(command -v $(MINGW) || echo 'no $(MINGW)')"; \
	  [ "$$found" = "$$(cat $@ 2>/dev/null)" ] || echo "$$found" > $@

$(VENV)/.installed: $(BIN)/python $(SOURCES) $(VENV)/.compilers
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
# every warning is an error; Sphinx says what it reads and writes as it goes (a build takes minutes)
docs: $(VENV)/.docs-installed
	$(BIN)/python -m sphinx -b html -E -W --keep-going docs docs/_build/html
	@echo "docs: open docs/_build/html/index.html"

# the MATLAB/Octave MEX gateway (matlab/, docs/matlab.md), compiled by Octave's mkoctfile from the C sources
octave:
	octave-cli --no-gui --norc --eval "addpath('$(CURDIR)/matlab'); disp(thermofriction.build())"

# the wheel and the sdist (the wheel built from the sdist), as CI tests them (tests/test_wheel_and_sources_fmu.py)
dist: $(BIN)/python
	$(BIN)/python -m pip install --quiet build
	$(BIN)/python -m build --outdir dist .

bench: install
	$(BIN)/python benchmarks/bench_simulate.py

clean:
	rm -rf $(VENV) build dist docs/_build docs/api/generated docs/gallery docs/sg_execution_times.rst
