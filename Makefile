# TeachPad: `make run` starts the pendant on the built-in simulator, `make test` runs every check.
# Both create .venv and install the project on a fresh machine by themselves.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed-stamp
export QT_QPA_PLATFORM ?= offscreen

.PHONY: run test lint bench bench-quick sim soak translations clean test-fonts dist dist-smoke

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
	$(BIN)/ruff check app ui tests benchmarks tools
	$(BIN)/ruff format --check app ui tests benchmarks tools
	$(BIN)/mypy
	$(BIN)/lint-imports

# Coverage floor (percent of app/ and ui/ lines run by the suite): a few points under the
# measured total; raise it as tests grow. Code in subprocesses is measured too, and code in
# QThreads (the link's worker: tests/conftest.py traces them; COV_QTHREADS=0 leaves them out).
COV_FLOOR ?= 93
COV_QTHREADS ?= 1

# The suite runs in TEST_WORKERS processes (pytest-xdist; each its own simulator ports, temporary
# folders and Qt application), one per core by default; TEST_WORKERS=0 runs it in this process.
TEST_WORKERS ?= $(shell nproc 2>/dev/null || echo 2)
# The lint (one core: mypy, mostly) runs beside the suite: it takes about a core for 2-3 min, so both at
# once take the suite's time, not the sum. Its output is printed when it ends; either failing fails.
LINT_LOG := $(VENV)/lint.log
test: $(STAMP)
	@$(MAKE) --no-print-directory lint > $(LINT_LOG) 2>&1 & lint=$$!; \
	TEACHPAD_COV_QTHREADS=$(COV_QTHREADS) $(BIN)/python -m pytest -n $(TEST_WORKERS) --dist worksteal \
		--cov=app --cov=ui \
		--cov-report=term-missing:skip-covered --cov-fail-under=$(COV_FLOOR); tests=$$?; \
	wait $$lint; linted=$$?; echo "--- make lint (beside the suite) ---"; cat $(LINT_LOG); \
	if [ $$linted -ne 0 ]; then echo "make test: the lint FAILED (above)"; fi; \
	[ $$tests -eq 0 ] && [ $$linted -eq 0 ]

# --- Font sets (issue 20) ---------------------------------------------------------------------
# The layout and relayout tests under fontconfig setups made for the run (tests/fonts): DejaVu
# only; URW base35 + Droid Sans Fallback; Noto Sans, Sans Mono, Sans CJK -- each at 100, 125 and
# 150 %, both languages, two processes at a time. A set whose fonts are missing is named with its
# Debian packages (`.ci/run` installs them; FONTSET_ROOT=/:DIR also looks in a `dpkg -x` tree).
# FONTSETS_ARGS, e.g. "--sets noto --scales 1.5" or "--require-all" (CI).
FONTSETS_ARGS ?=
test-fonts: $(STAMP)
	$(BIN)/python -m tests.fonts.run $(FONTSETS_ARGS)
# --- end of font sets ----------------------------------------------------------------------------

bench: $(STAMP)
	$(BIN)/python -m benchmarks.run

bench-quick: $(STAMP)
	$(BIN)/python -m benchmarks.run --quick

# The real window against the simulator for SOAK_MINUTES of random operator actions (seeded:
# SOAK_SEED repeats a run), under faulthandler, Qt warnings fatal, core dumps on; fails on any
# crash, warning or traceback (tests/soak/run.py). Not part of `make test`.
SOAK_MINUTES ?= 30
SOAK_SEED ?=
soak: $(STAMP)
	$(BIN)/python -m tests.soak.run --minutes $(SOAK_MINUTES) $(if $(SOAK_SEED),--seed $(SOAK_SEED))

# Collect every tr() string, fill Chinese from resources/translations/*_zh_CN.txt, compile the .qm.
translations: $(STAMP)
	$(BIN)/pyside6-lupdate -no-obsolete $$(find app ui -name '*.py' | sort) -ts resources/translations/teachpad_zh_CN.ts
	$(BIN)/python resources/translations/merge.py resources/translations/teachpad_zh_CN.ts resources/translations/*_zh_CN.txt
	$(BIN)/pyside6-lrelease resources/translations/teachpad_zh_CN.ts -qm ui/i18n/teachpad_zh_CN.qm

# The bundle that needs no Python (README, "Bundle"): dist/teachpad/ holds the executables
# teachpad, teachpad-cli, teachpad-sim and teachpad-gateway over one _internal/ folder (Qt, numpy,
# Python, paho-mqtt, protobuf, the translations, the robot profiles, the gateway's .proto). PyInstaller is pinned in pyproject.toml's `dist` extra.
# `make dist-smoke` runs the bundle from a clean environment (tools/dist_smoke.py).
DIST_STAMP := $(VENV)/.dist-stamp
$(DIST_STAMP): $(STAMP)
	$(BIN)/python -m pip install --quiet -e '.[test,dist]'
	touch $(DIST_STAMP)

dist: $(DIST_STAMP)
	$(BIN)/pyinstaller --noconfirm --log-level WARN --distpath dist --workpath build/pyinstaller \
		packaging/teachpad.spec

dist-smoke: dist
	$(BIN)/python tools/dist_smoke.py dist/teachpad

clean:
	rm -rf build dist $(VENV) .pytest_cache .mypy_cache .ruff_cache .coverage .coverage.* htmlcov
