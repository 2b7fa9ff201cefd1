# Two commands do all the set-up on a fresh machine:
#   make demo  - create the virtual environment, install everything, run the thesis demo headless
#   make test  - create the virtual environment if needed and run the whole test suite
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed

.PHONY: demo test bench clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet -e '.[all,dev]'
	touch $(STAMP)

demo: $(STAMP)
	MUJOCO_GL=$${MUJOCO_GL:-egl} $(VENV)/bin/pycram demo

test: $(STAMP)
	MUJOCO_GL=$${MUJOCO_GL:-egl} $(PY) -m pytest

bench: $(STAMP)
	$(PY) benchmarks/language.py

clean:
	rm -rf $(VENV)
