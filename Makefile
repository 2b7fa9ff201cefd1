# Two commands do all the set-up on a fresh machine:
#   make demo  - create the virtual environment, install everything, run the thesis demo headless
#   make test  - create the virtual environment if needed, install ROS 1 (scripts/install_ros.sh)
#                and Chromium for the view's browser test (scripts/install_chromium.sh), and run
#                the whole test suite
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
ROS    := $(VENV)/.ros-installed
CHROMIUM := $(VENV)/.chromium-installed

.PHONY: demo test bench docs check wheel ros clean lint types

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet -e '.[all,dev]'
	touch $(STAMP)

# ROS 1 from Debian's packages (apt-get only when something is missing) + generated messages.
$(ROS): $(STAMP) scripts/install_ros.sh $(wildcard pycram/backends/ros/interfaces/*/*.msg pycram/backends/ros/interfaces/*/*.action pycram/backends/ros/interfaces/*/*.srv) pycram/backends/ros/interfaces/generate.py
	scripts/install_ros.sh $(VENV)
	touch $(ROS)

ros: $(ROS)

# Debian's headless Chromium for tests/view (apt-get only when `chromium` is missing).
$(CHROMIUM): scripts/install_chromium.sh
	scripts/install_chromium.sh
	touch $(CHROMIUM)

demo: $(STAMP)
	MUJOCO_GL=$${MUJOCO_GL:-egl} $(VENV)/bin/pycram demo

test: $(STAMP) $(ROS) $(CHROMIUM)
	MUJOCO_GL=$${MUJOCO_GL:-egl} $(PY) -m pytest

bench: $(STAMP)
	$(PY) benchmarks/language.py

# The documentation site, built into site/ with warnings as errors (offline: no fonts or CDN).
docs: $(STAMP) $(ROS)
	NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs build --strict --quiet

# Lint, format check and the layering contracts (zero findings; CI runs it).
lint: $(STAMP)
	$(VENV)/bin/ruff check .
	$(VENV)/bin/ruff format --check .
	$(VENV)/bin/lint-imports

# Type check (zero errors; CI runs it): strict on the language core, default settings on the rest
# (the configuration is in pyproject.toml).
types: $(STAMP)
	$(VENV)/bin/mypy

# Lint, format, layering, types and docs: everything CI checks besides the wheel and the tests.
check: lint
	$(VENV)/bin/mypy
	NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs build --strict --quiet

# Build the wheel, install it into a fresh virtual environment, run its CLI and a small plan.
wheel: $(STAMP)
	PYTHON=$(PY) scripts/check_wheel.sh

clean:
	rm -rf $(VENV) site dist
