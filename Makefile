# balloon-cg developer targets. `make run` and `make test` each install first, so a fresh clone needs nothing else.
PYTHON ?= python3
OUT ?= out
RUN_FLAGS ?=
PAPER_OUT ?= paper-figures
PAPER_FLAGS ?=
# pip byte-compiles every module it installs (numba's, scipy's and matplotlib's own tests included: ~10 s of one core,
# half of a fresh install's CPU, benchmarks/make_run.py); Python writes the bytecode of what is imported at its first
# import instead. Where PYTHONDONTWRITEBYTECODE is set Python never writes it, so there the install compiles it all.
PIP_INSTALL = $(PYTHON) -m pip install --quiet $(if $(PYTHONDONTWRITEBYTECODE),,--no-compile)

.PHONY: install install-dev regenerate api-docs test run paper bench clean

# Editable like install-dev. A regular `pip install .` before or after is fine too: it ships the generated kernels
# and the scenes, and numba's cache goes to ~/.cache/balloon-cg/numba, never into site-packages
# (tests/test_packaging.py builds and inspects the wheel and runs install, run and test installs in a fresh venv).
install:
	$(PIP_INSTALL) -e .

install-dev:
	$(PIP_INSTALL) -e ".[test,codegen]"

regenerate:
	$(PYTHON) -m codegen generated

# docs/api_reference.md from the public API's docstrings (tests/test_api_reference.py fails when it is stale)
api-docs: install-dev
	$(PYTHON) benchmarks/api_reference.py

test: install-dev
	$(PYTHON) -m pytest -q

run: install
	$(PYTHON) -m balloon_cg.app.default_run $(OUT) $(RUN_FLAGS)

# every figure of the paper (docs/paper.md) into $(PAPER_OUT)/figN.pdf; the runs are kept in $(PAPER_OUT)/runs and
# reused while their scenes are unchanged. PAPER_FLAGS: e.g. "--width 3.5 --stability axisymmetric", "--quick", or
# "--allow-partial" (exit 0 although a run drawn is flagged incomplete; they are named on stderr either way).
paper: install
	$(PYTHON) -m balloon_cg figure all -o $(PAPER_OUT) --force $(PAPER_FLAGS)

bench: install-dev
	$(PYTHON) benchmarks/primary_branch.py

clean:
	rm -rf build dist *.egg-info $(OUT) $(PAPER_OUT)
