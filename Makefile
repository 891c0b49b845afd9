# Two set-up commands: `make run` and `make test`. Both create .venv when it is missing and install
# the project into it (the CPU build of torch first: a plain `torch` requirement would pull CUDA).
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: run test bench verify datasets headline headline-select headline-fly clean

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

# the headline that decides (docs/test-seeds.md, "The headline's test block"): every reported policy of the v2
# suites on 200 validation seeds chooses the best classical and learned policy per suite (the selection file,
# docs/data/headline-selection.json: commit it), then the selected policies fly the named test block 12,000-12,199
# once (and the 50 development seeds for continuity; both logged in docs/data/test-flights.jsonl), and the
# results page docs/results.md is written from the record docs/data/headline.json
headline: headline-select headline-fly

headline-select: $(STAMP)
	$(VENV)/bin/lvgym headline select

headline-fly: $(STAMP)
	$(VENV)/bin/lvgym headline fly
	$(VENV)/bin/lvgym headline page

# rollouts of every classical baseline and shipped learned policy on every v2 suite, as Minari datasets
# (validation seeds; into MINARI_DATASETS_PATH, default ~/.minari/datasets): the data offline RL starts from
# (docs/datasets.md)
DATASET_SUITES ?= smile-v2 smile-v2-maxq-gust smile-v2-faults stratos-tvc-v2 slender-v2
DATASET_EPISODES ?= 50
datasets: $(STAMP)
	$(VENV)/bin/lvgym dataset --policies classical learned --suites $(DATASET_SUITES) --episodes $(DATASET_EPISODES)

clean:
	rm -rf $(VENV) .pytest_cache
