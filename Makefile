# Two set-up commands: `make run` and `make test`. Both create .venv when it is missing and install
# the project into it (the CPU build of torch first: a plain `torch` requirement would pull CUDA).
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: run test bench verify datasets clean

$(STAMP): pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --upgrade pip
	$(PY) -m pip install torch==2.13.0
	$(PY) -m pip install -e ".[dev]"
	touch $(STAMP)

run: $(STAMP)
	$(PY) evaluate.py

verify: $(STAMP)
	$(PY) -m lvgym.verify

test: $(STAMP)
	$(PY) -m pytest -n auto

bench: $(STAMP)
	$(VENV)/bin/lvgym bench
	$(PY) -m lvgym.bench_envs

# rollouts of every classical baseline and shipped learned policy on every v2 suite, as Minari datasets
# (validation seeds; into MINARI_DATASETS_PATH, default ~/.minari/datasets): the data offline RL starts from
# (docs/datasets.md)
DATASET_SUITES ?= smile-v2 smile-v2-maxq-gust smile-v2-faults stratos-tvc-v2 slender-v2
DATASET_EPISODES ?= 50
datasets: $(STAMP)
	$(VENV)/bin/lvgym dataset --policies classical learned --suites $(DATASET_SUITES) --episodes $(DATASET_EPISODES)

clean:
	rm -rf $(VENV) .pytest_cache
