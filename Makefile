# partlab: `make run` starts the app on a demo clip, `make test` runs the tests.
# Both create (or reuse) a virtual environment in .venv and install what they need.
# `make test` lints first (ruff, configured in pyproject.toml: a complexity limit of 15 per function).

PYTHON ?= python3
VENV ?= .venv
PY := $(VENV)/bin/python
HOST ?= 127.0.0.1
PORT ?= 8501
export PARTLAB_DATA ?= $(CURDIR)/partlab-data
# Installs take the versions in constraints.txt (what the tests and measurements ran with);
# `make test CONSTRAINTS=` installs the newest releases pyproject.toml allows instead.
CONSTRAINTS ?= constraints.txt
PIP_C := $(if $(CONSTRAINTS),-c $(CONSTRAINTS))

.PHONY: run test venv peers clean

$(VENV)/bin/python:
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip

# Re-install whenever pyproject.toml or constraints.txt changes.
$(VENV)/.installed: pyproject.toml $(CONSTRAINTS) | $(VENV)/bin/python
	$(PY) -m pip install --quiet $(PIP_C) -e .
	touch $@

$(VENV)/.installed-test: pyproject.toml $(CONSTRAINTS) $(VENV)/.installed
	$(PY) -m pip install --quiet $(PIP_C) -e '.[test]'
	# HOTA (optional): trackeval's metadata pins opencv-python, which would overwrite our headless
	# OpenCV in cv2/; its metrics only need numpy and scipy, so install it without dependencies.
	$(PY) -m pip install --quiet --no-deps 'trackeval==1.3.0'
	touch $@

venv: $(VENV)/.installed

# Peers whose pins conflict with ours, each in its own venv, called by the tests as subprocesses
# (tests/labelling/formats/test_peers_venv.py, tests/labelling/test_labelstudio_server.py):
# Label Studio (server, converter, tools) and FiftyOne. The Label Studio data directory is initialised
# once (its migrations take minutes); the end-to-end test starts a server on a copy of it.
PEERS ?= .venv-peers
$(PEERS)/%/.installed:
	$(PYTHON) -m venv $(PEERS)/$*
	$(PEERS)/$*/bin/python -m pip install --quiet $(if $(filter labelstudio,$*),label-studio label-studio-converter,fiftyone)
	touch $@

$(PEERS)/labelstudio-data/label_studio.sqlite3: $(PEERS)/labelstudio/.installed
	LABEL_STUDIO_BASE_DATA_DIR=$(CURDIR)/$(PEERS)/labelstudio-data $(PEERS)/labelstudio/bin/label-studio init partlab \
	  --username test@example.com --password partlab-test --user-token abcdef0123456789abcdef0123456789 \
	  --enable-legacy-api-token --agree-fix-sqlite --quiet

peers: $(PEERS)/labelstudio/.installed $(PEERS)/fiftyone/.installed $(PEERS)/labelstudio-data/label_studio.sqlite3

run: $(VENV)/.installed
	$(PY) -m partlab.app.demo
	$(PY) -m partlab app --host $(HOST) --port $(PORT)

test: $(VENV)/.installed-test peers
	$(PY) -m ruff check .
	$(PY) -m pytest $(PYTEST_ARGS)

clean:
	rm -rf $(VENV) $(PEERS) build *.egg-info
