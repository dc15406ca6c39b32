# One Makefile for people and CI: `make demo` (the main job: the whole pipeline at a small
# budget, ending with the path of its HTML report) and `make test`.
# Each target creates or refreshes the local virtual environment (.venv) when it is
# missing or older than pyproject.toml; nothing else is needed on a fresh machine with
# Python 3.11.

PYTHON ?= $(shell command -v python3.11 || command -v python3)
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
# torch first, pinned: that CPU build is on this machine's disk; an unpinned torch pulls a
# multi-GB CUDA build from PyPI.
TORCH  := torch==2.13.0
# Extra pip arguments for torch. Off this machine, take the CPU build from PyTorch's index:
#   make demo TORCH_PIP_ARGS="--index-url https://download.pytorch.org/whl/cpu"
TORCH_PIP_ARGS ?=
ifneq ($(strip $(TORCH_PIP_ARGS)),)
ifneq ($(wildcard $(STAMP)),)
$(warning TORCH_PIP_ARGS is ignored: .venv is already set up (make clean, then make again, to install torch with them))
endif
endif

.PHONY: all demo test test-slow lint format typecheck bench networks clean

all: test

$(STAMP): pyproject.toml
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet $(TORCH) $(TORCH_PIP_ARGS)
	$(BIN)/python -m pip install --quiet -e '.[dev,ray,hwenv]'
	@touch $(STAMP)

venv: $(STAMP)

demo: $(STAMP)
	$(BIN)/python -m sumo_ayss.pipeline configs/demo.yaml

test: $(STAMP)
	$(BIN)/python -m pytest

test-slow: $(STAMP)
	$(BIN)/python -m pytest -m slow

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .

format: $(STAMP)
	$(BIN)/ruff format .
	$(BIN)/ruff check --fix .

typecheck: $(STAMP)
	$(BIN)/mypy sumo_ayss

bench: $(STAMP)
	$(BIN)/python benchmarks/env_throughput.py
	$(BIN)/python benchmarks/throughput.py

networks: $(STAMP)
	$(BIN)/python -m sumo_ayss.sim.network

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache .ruff_cache .mypy_cache
