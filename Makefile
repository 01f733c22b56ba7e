# partlab: `make run` starts the app on a demo clip, `make test` runs the tests.
# Both create (or reuse) a virtual environment in .venv and install what they need.
# `make test` lints first (ruff, configured in pyproject.toml: a complexity limit of 15 per function).

PYTHON ?= python3
VENV ?= .venv
PY := $(VENV)/bin/python
HOST ?= 127.0.0.1
PORT ?= 8501
export PARTLAB_DATA ?= $(CURDIR)/partlab-data

.PHONY: run test venv clean

$(VENV)/bin/python:
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip

# Re-install whenever pyproject.toml changes.
$(VENV)/.installed: pyproject.toml | $(VENV)/bin/python
	$(PY) -m pip install --quiet -e .
	touch $@

$(VENV)/.installed-test: pyproject.toml $(VENV)/.installed
	$(PY) -m pip install --quiet -e '.[test]'
	# HOTA (optional): trackeval's metadata pins opencv-python, which would overwrite our headless
	# OpenCV in cv2/; its metrics only need numpy and scipy, so install it without dependencies.
	$(PY) -m pip install --quiet --no-deps 'trackeval==1.3.0'
	touch $@

venv: $(VENV)/.installed

run: $(VENV)/.installed
	$(PY) -m partlab.app.demo
	$(PY) -m partlab app --host $(HOST) --port $(PORT)

test: $(VENV)/.installed-test
	$(PY) -m ruff check .
	$(PY) -m pytest $(PYTEST_ARGS)

clean:
	rm -rf $(VENV) build *.egg-info
