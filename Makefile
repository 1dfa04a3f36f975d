# Two commands: `make book` builds the HTML, `make test` runs every check.
# Both create .venv from requirements.txt when it is missing or older than it.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: book test benchmark clean

$(STAMP): requirements.txt pyproject.toml
	@echo "Installing .venv from requirements.txt and pyproject.toml (a few minutes the first time)..."
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet -r requirements.txt
	touch $(STAMP)

book: $(STAMP)
	$(BIN)/jupyter-book build --all -W -n --keep-going .
	@echo "Book built: $(CURDIR)/_build/html/index.html"

test: $(STAMP)
	$(BIN)/python -m pytest

benchmark: $(STAMP)
	$(BIN)/python benchmarks/bench_switched.py
	$(BIN)/python benchmarks/bench_eight_sweep.py

clean:
	rm -rf _build
