# Two set-up commands: `make run` and `make test`. Both create .venv when it is missing and install
# the project into it (the CPU build of torch first: a plain `torch` requirement would pull CUDA).
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: run test bench verify clean

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
	$(PY) -m lvgym.bench
	$(PY) -m lvgym.bench_envs

clean:
	rm -rf $(VENV) .pytest_cache
