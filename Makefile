# Two commands: `make book` builds the HTML, `make test` runs every check.
# Both create .venv from requirements.txt when it is missing or older than it.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: book test test-portable chapter pdf lab benchmark book-times clean mutation

$(STAMP): requirements.txt pyproject.toml
	@echo "Installing .venv from requirements.txt and pyproject.toml (a few minutes the first time)..."
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet -r requirements.txt
	touch $(STAMP)

# The pages are executed two at a time into the execution cache (tools/preexecute.py, which
# empties it first), then the build reads their outputs from it (_config.yml: execute).
# The build's output goes to the terminal and to _build/build.log (its time set back to when
# the build began), its exit status to _build/build.rc: `make test` reuses a build that is
# current and reads its warnings from that log (tests/conftest.py, fixture built_book).
book: $(STAMP)
	mkdir -p _build && rm -f _build/build.rc && touch _build/build.start
	{ PYTHONWARNINGS=default $(BIN)/python tools/preexecute.py 2>&1 && \
	  PYTHONWARNINGS=default $(BIN)/jupyter-book build --all -W -n --keep-going . 2>&1; \
	  echo $$? > _build/build.rc; } | tee _build/build.log
	touch -r _build/build.start _build/build.log
	@test "$$(cat _build/build.rc)" = 0 || { echo "Book build failed (see _build/build.log)"; exit 1; }
	@echo "Book built: $(CURDIR)/_build/html/index.html"

# One page at a time: `make chapter CH=08` (a chapter's number, or a page: CH=report, intro,
# errata, methods) executes that page alone into the execution cache, keeping every other page's
# entry there (tools/preexecute.py --keep-cache), then builds the HTML again, reading every page's
# outputs from the cache. The pages that quote a chapter's results (the report, the errata, the
# front page) keep what the cache holds for them until they are executed again themselves.
chapter: $(STAMP)
	@test -n "$(CH)" || { echo "usage: make chapter CH=08 (a chapter's number, or CH=report, intro, errata, methods)"; exit 2; }
	mkdir -p _build
	PYTHONWARNINGS=default $(BIN)/python tools/preexecute.py --keep-cache --jobs 1 $(CH)
	$(BIN)/jupyter-book build --all -n --keep-going .

# The book as one PDF, _build/pdf/book.pdf, and the library reference apart, _build/pdf/reference.pdf
# (tools/pdf.py): the single-page HTML build,
# which reads every page's outputs from the execution cache (`make book` fills it first when
# it is missing), printed by headless Chromium once MathJax has typeset the math, each
# interactive figure as a static image. Needs Debian's chromium (.ci/run installs it).
pdf: $(STAMP)
	@test -d _build/.jupyter_cache || $(MAKE) --no-print-directory book
	$(BIN)/python tools/pdf.py

# The book's build runs in the background (as `make book` runs it, its output in _build/book.out)
# while the other tests run on two workers (pytest-xdist); then the build and browser tests read
# that build. A current build left by `make book` is reused instead (tests/conftest.py).
# The build is the longest path: the workers run niced and single-threaded (numba, OpenMP,
# BLAS), so that three processes do not oversubscribe two cores (measured: 5 min 46 s instead
# of 6 min 17 s, 10.4 instead of 11.6 min of CPU).
test: $(STAMP)
	@mkdir -p _build
	@if [ -z "$$BOOK_REBUILD" ] && $(BIN)/python -c "import sys; sys.path.insert(0, 'tests'); \
	      import conftest; sys.exit(conftest._current_build() is None)"; \
	  then echo "Reusing the current build in _build"; : > _build/book.out; \
	  else echo "Building the book in the background (output: _build/book.out)"; \
	       $(MAKE) --no-print-directory book > _build/book.out 2>&1 & fi; \
	NUMBA_NUM_THREADS=1 OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 nice -n 10 $(BIN)/python -m pytest -n 2 --dist worksteal -m "not book and not browser"; fast=$$?; \
	wait; \
	BOOK_REBUILD= $(BIN)/python -m pytest -m "book or browser"; slow=$$?; \
	test $$fast = 0 && test $$slow = 0

# The fast tests, then the book, again under another machine's arithmetic, emulated on this one (README:
# "Another machine's arithmetic"): numba compiles for its generic x86-64 target (no AVX, no
# FMA contraction) into a cache of its own, so that it neither reads nor overwrites the native
# one; OpenBLAS (numpy's and scipy's) runs its most generic kernel; numpy's SIMD loops above
# the x86-64-v2 baseline (AVX2/FMA3, AVX-512) are switched off; BLAS, OpenMP and numba run one
# thread, so no reduction is split differently. A bound that holds only on this CPU fails here.
PORTABLE_ENV := NUMBA_CPU_NAME=generic NUMBA_CACHE_DIR=$(CURDIR)/_build/numba-generic \
	OPENBLAS_CORETYPE=Prescott NPY_DISABLE_CPU_FEATURES="X86_V3 X86_V4 AVX512_ICL AVX512_SPR" \
	NUMBA_NUM_THREADS=1 OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1 \
	PYTHONHASHSEED=0

# Then the book's pages themselves, executed afresh under the same arithmetic (their `assert`s run
# there), and the book's tests on that build (warnings, stderr, the kinds of the glued numbers). The
# results the pages share (`_build/.cache`) are emptied first, so that no page reads what the native
# build computed. This build replaces the native one in _build.
test-portable: $(STAMP)
	@mkdir -p _build/numba-generic
	$(PORTABLE_ENV) nice -n 10 $(BIN)/python -m pytest -n 2 --dist worksteal -m "not book and not browser" -p no:cacheprovider
	rm -rf _build/.cache
	$(PORTABLE_ENV) $(MAKE) --no-print-directory book > _build/book-portable.out 2>&1 || \
	  { tail -n 60 _build/book-portable.out; echo "The book failed under the portable arithmetic (_build/book-portable.out)"; exit 1; }
	$(PORTABLE_ENV) $(BIN)/python -m pytest -m "book and not packaging" -p no:cacheprovider

# JupyterLab on the book's folder, on the loopback address: a chapter (chapters/*.md, a MyST text
# notebook) opens as a notebook through jupytext, and runs in the project's kernel (.venv's python3).
# Its outputs stay in the browser, never in the .md (a cell's outputs are not saved to the text).
lab: $(STAMP)
	$(BIN)/jupyter lab --ServerApp.ip=127.0.0.1 --ServerApp.allow_root=True \
	  --LabApp.check_for_updates_class=jupyterlab.NeverCheckForUpdate --ServerApp.root_dir=$(CURDIR) chapters

benchmark: $(STAMP)
	$(BIN)/python benchmarks/bench_switched.py
	$(BIN)/python benchmarks/bench_locators.py
	$(BIN)/python benchmarks/bench_eight_sweep.py
	$(BIN)/python benchmarks/bench_scale.py
	$(BIN)/python benchmarks/bench_book.py

# Where the book's build time goes: each page's and each heavy cell's wall and CPU time, the pages
# executed one after another in a fresh copy of the book (benchmarks/book_times.py).
# PAGES="chapters/04_limits report" for some; MIN=0.5 lists the cells above 0.5 s.
book-times: $(STAMP)
	$(BIN)/python benchmarks/book_times.py --min $(or $(MIN),1) $(PAGES)

clean:
	rm -rf _build

# Mutation testing with mutmut, by hand (not in CI), niced: the core modules, the verdict
# procedure, lib/weighting/circle.py and the ten modules of lib/paper (mutation/run.py, TESTS).
# On 2 idle cores the core modules and the verdict procedure take about 20 min (the six core
# modules other than allocation 6.2 min, allocation 11.4, the verdict procedure 1.0);
# weighting.circle takes 17 min and lib/paper 16 (then about 10 to write its survivors' diffs):
# give those two their own run. Appends the score and the surviving mutants to mutation/REPORT.md.
# MODULES="angles params" limits it to some of them.
mutation: $(STAMP)
	$(BIN)/python mutation/run.py $(MODULES)
