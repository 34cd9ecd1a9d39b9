# TeachPad: `make run` starts the pendant on the built-in simulator, `make test` runs every check.
# Both create .venv and install the project on a fresh machine by themselves.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed-stamp
export QT_QPA_PLATFORM ?= offscreen

.PHONY: run test lint bench bench-quick sim translations clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test]'
	touch $(STAMP)

run: QT_QPA_PLATFORM=
run: $(STAMP)
	$(BIN)/teachpad --sim

sim: $(STAMP)
	$(BIN)/teachpad-sim

lint: $(STAMP)
	$(BIN)/ruff check app ui tests benchmarks
	$(BIN)/mypy
	$(BIN)/lint-imports

test: lint
	$(BIN)/python -m pytest

bench: $(STAMP)
	$(BIN)/python -m benchmarks.run

bench-quick: $(STAMP)
	$(BIN)/python -m benchmarks.run --quick

# Collect every tr() string, fill Chinese from resources/translations/*_zh_CN.txt, compile the .qm.
translations: $(STAMP)
	$(BIN)/pyside6-lupdate -no-obsolete $$(find app ui -name '*.py' | sort) -ts resources/translations/teachpad_zh_CN.ts
	$(BIN)/python resources/translations/merge.py resources/translations/teachpad_zh_CN.ts resources/translations/*_zh_CN.txt
	$(BIN)/pyside6-lrelease resources/translations/teachpad_zh_CN.ts -qm ui/i18n/teachpad_zh_CN.qm

clean:
	rm -rf $(VENV) .pytest_cache .mypy_cache .ruff_cache
