# balloon-cg developer targets. `make run` and `make test` each install first, so a fresh clone needs nothing else.
PYTHON ?= python3
OUT ?= out

.PHONY: install install-dev regenerate test run bench clean

# Editable like install-dev, so that `make run` and `make test` never leave two installs of different kinds (a
# regular install leaves numba cache files in site-packages that would shadow a later editable one).
# `pip install .` ships the generated kernels too (tests/test_packaging.py builds and inspects the wheel).
install:
	$(PYTHON) -m pip install --quiet -e .

install-dev:
	$(PYTHON) -m pip install --quiet -e ".[test,codegen]"

regenerate:
	$(PYTHON) -m codegen generated

test: install-dev
	$(PYTHON) -m pytest -q

run: install
	$(PYTHON) -m balloon_cg.app.default_run $(OUT)

bench: install-dev
	$(PYTHON) benchmarks/primary_branch.py

clean:
	rm -rf build dist *.egg-info $(OUT)
