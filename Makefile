# apair: `make` sets up .venv, regenerates every derivation and kernel, builds the C library and runs
# the demonstration; `make test` runs the whole suite (including `make check`).
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
PY := $(BIN)/python
DEPS_STAMP := $(VENV)/.deps-stamp
CFLAGS_STRICT := -std=c99 -Wall -Wextra -Werror -pedantic -O2
CHECK_DIR := build/check-generated

.PHONY: all venv generate install varieties lib examples demo check test test-fast lint docs bench clean ik-counts browser pictures clang

all: generate install varieties lib examples demo

$(PY):
	$(PYTHON) -m venv $(VENV)

# Dependencies (and a first, editable install of the package) whenever pyproject.toml changes.
$(DEPS_STAMP): pyproject.toml setup.py | $(PY)
	$(PY) -m pip install --quiet --upgrade pip "setuptools>=77" wheel
	$(PY) -m pip install --quiet -e ".[dev]"
	touch $@

venv: $(DEPS_STAMP)

generate: $(DEPS_STAMP)
	PYTHONPATH=. $(PY) -m codegen

# The example chains' constraint varieties (exact), computed by the installed runtime's engine.
varieties: install
	PYTHONPATH=. $(PY) -m codegen.varieties

# The package is installed editable: the source tree is the package (src/apair, with generated/,
# derivations/ and codegen/ mapped into it as apair.generated, apair.derivations, apair.codegen), so
# the tests see an edit of Python at once. Only the C binding apair._native is built, in place,
# and rebuilt when its sources change.
EXT_SUFFIX := $(shell $(PYTHON) -c "import sysconfig; print(sysconfig.get_config_var('EXT_SUFFIX'))")
NATIVE := src/apair/_native$(EXT_SUFFIX)
NATIVE_SOURCES = $(wildcard generated/c/*.c generated/c/*.h src/csrc/*.c src/csrc/*.h src/apair/_native*.c src/apair/_native.h) setup.py
install: $(NATIVE)
$(NATIVE): $(DEPS_STAMP) $(NATIVE_SOURCES)
	$(PY) -m pip install --quiet --no-deps --no-build-isolation -e .
	touch $@

# The C kernels as a plain shared library, built with the strict flags users may have: one object
# per generated source, compiled in parallel on every core.
NPROC := $(shell nproc 2>/dev/null || echo 2)
C_SOURCES = $(wildcard generated/c/*.c)
C_OBJECTS = $(patsubst generated/c/%.c,build/obj/%.o,$(C_SOURCES))
lib:
	$(MAKE) --no-print-directory -j$(NPROC) build/libapair.so
build/libapair.so: $(C_OBJECTS)
	gcc -shared $^ -o $@ -lm
build/obj/%.o: generated/c/%.c $(wildcard generated/c/*.h)
	@mkdir -p build/obj
	gcc $(CFLAGS_STRICT) -fPIC -c $< -o $@

# The example chain's own code (apair codegen), committed like generated/ and compared by make check.
EXAMPLE_CODE := examples/codegen/chain4a
EXAMPLE_CODEGEN = $(BIN)/apair codegen examples/4a_chain.toml --prefix chain4a --out
examples: install
	$(EXAMPLE_CODEGEN) $(EXAMPLE_CODE)

demo: install
	$(BIN)/apair demo examples/4a_chain.toml

# Regenerate into a scratch folder and fail if it differs from the committed generated/.
check: install
	rm -rf $(CHECK_DIR) $(CHECK_DIR)-example
	PYTHONPATH=. $(PY) -m codegen --out $(CHECK_DIR)
	PYTHONPATH=. $(PY) -m codegen.varieties --out $(CHECK_DIR)
	diff -r -x __pycache__ -x ik_counts.json generated $(CHECK_DIR) || \
	  (echo "generated/ is out of date with the derivations: run make generate and commit" >&2; exit 1)
	$(EXAMPLE_CODEGEN) $(CHECK_DIR)-example
	diff -r $(EXAMPLE_CODE) $(CHECK_DIR)-example || \
	  (echo "$(EXAMPLE_CODE) is out of date: run make examples and commit" >&2; exit 1)

test: install lib check browser clang
	$(PY) -m pytest -q -n $(NPROC) --durations=30

# The fast tier (a few minutes): every test not marked slow, without regenerating generated/.
test-fast: install lib browser
	$(PY) -m pytest -q -m "not slow"

# Lint, format, types and the import graph (a layered tree, .importlinter); the same checks run
# before a commit with `pre-commit install` (.pre-commit-config.yaml).
lint: $(DEPS_STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	$(BIN)/mypy
	$(BIN)/lint-imports .importlinter

# The documentation site (MkDocs) in build/site; any warning or broken link fails the build.
docs: $(DEPS_STAMP)
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict

# The system programs the tests drive, found or installed by tests/sysdeps.py. A Chromium for the
# viewer's browser test (Playwright, from the test extra, launches it): $CHROMIUM, else one on PATH,
# else Playwright's own; else Debian's package chromium (apt-get as root, or with a sudo that asks for
# no password), else Playwright's download into ~/.cache (no root); else it stops with the commands to
# run. clang for the C checks: Debian's clang and libclang-rt-dev the same way, else a note (those
# checks are then skipped, saying so).
browser: $(DEPS_STAMP)
	@$(PY) tests/sysdeps.py browser
clang:
	@$(PYTHON) tests/sysdeps.py clang

# The documentation's pictures of the MuJoCo model and the viewer (off-screen OpenGL by EGL, Chromium).
pictures: install browser
	$(PY) docs/pictures.py

# Timings (never asserted by tests): results in bench/results.json. The peers (the bench extra of
# pyproject.toml) are installed here only; builds of the C/C++ peers are kept in build/bench.
BENCH_STAMP := $(VENV)/.bench-stamp
$(BENCH_STAMP): pyproject.toml | $(DEPS_STAMP)
	$(PY) -m pip install --quiet $$($(PY) -c "import tomllib; print(' '.join(\
	  tomllib.load(open('pyproject.toml', 'rb'))['project']['optional-dependencies']['bench']))")
	touch $@

# The generic inverse-kinematics solution counts of every R/A pattern (apair show ik_counts):
# monodromy on a random design of each pattern, and the trace test for start sets of up to 48
# solutions, slower than `make` (about half an hour). `... --trace N --update` judges the sets of up to N
# solutions of the stored rows again and keeps the others.
ik-counts: install
	$(PY) -m apair.ik.homotopy.counts generated/ik_counts.json 6 --trace 48

# A full run (no BENCH_ARGS) also replaces docs/benchmarks/results.json, which the documentation's
# benchmark tables are rendered from (commit it).
bench: install $(BENCH_STAMP)
	PYTHONPATH=. $(PY) bench/run.py $(BENCH_ARGS)
	@if [ -z "$(BENCH_ARGS)" ]; then cp bench/results.json docs/benchmarks/results.json && \
	  echo "docs/benchmarks/results.json updated: the documentation's benchmark tables come from it"; fi

clean:
	rm -rf build .venv *.egg-info src/*.egg-info src/apair/_native*.so
