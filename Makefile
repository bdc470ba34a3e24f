# rockmech: every target bootstraps its own virtual environment (.venv) on first use.
PY ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-stamp

.PHONY: install demo test test-all lint typecheck pyright schema bench numerics report-png serve dist install-check clean

$(STAMP): pyproject.toml
	$(PY) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[dev]"
	touch $(STAMP)

install: $(STAMP)

## Main job on bundled data: rectangular walls on El Centro 1940, results in out/.
demo: $(STAMP)
	$(BIN)/rockmech demo --out out

## The whole test suite: lint, format check, types, schema drift, then pytest.
## The quick loop: everything but the tests marked slow (fuzzing, the load test, the
## kill-at-every-step test, the wheel and Docker builds...): under 6 minutes on 2 cores.
test: lint typecheck schema
	$(BIN)/python -m pytest -n auto -m "not slow"

## The whole suite, slow tests included: what CI runs (.ci/run) and the README's test command.
test-all: lint typecheck schema
	$(BIN)/python -m pytest -n auto

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .

typecheck: $(STAMP)
	$(BIN)/mypy
	$(BIN)/mypy --config-file mypy-py39.ini

## The wheel and the sdist, in dist/.
dist: $(STAMP)
	rm -rf dist
	$(BIN)/python -m build --outdir dist .

## The wheel installed as a user would, in a fresh virtual environment: with no extras
## (--version, --help, demo, import rockmech), then with geometry,service (constants and
## one request to rockmech serve). .ci/run runs it after `make test-all`.
install-check: dist
	.ci/install_check dist

## The Rhino glue against RhinoCommon (pyright + rhino-stubs-typed; needs node on PATH).
## `make test-all` runs the same check in tests/rhino_glue/test_static.py.
pyright: $(STAMP)
	$(BIN)/pyright --pythonpath $(BIN)/python

schema: $(STAMP)
	$(BIN)/python -m shared_schema.export --check

## Benchmarks (not part of the test suite): tables on stdout, figures in docs/.
bench: $(STAMP)
	$(BIN)/python benchmarks/work_precision.py
	$(BIN)/python benchmarks/envelope_speed.py
	$(BIN)/python benchmarks/geometry_speed.py
	$(BIN)/python benchmarks/records_speed.py
	$(BIN)/python benchmarks/load.py
	$(BIN)/python benchmarks/cli_start.py

## Numerics report (docs/numerics.md, docs/img/, solver_service/data/linearisation_map.npz):
## work precision of every integrator, stiff cases, linearisation map, extreme-case sweep.
numerics: $(STAMP)
	$(BIN)/python benchmarks/numerics_wp.py
	$(BIN)/python benchmarks/stiff.py
	$(BIN)/python benchmarks/linearisation_map.py
	$(BIN)/python benchmarks/extremes.py

## Page one of the bundled assessment report as printed (docs/img/report_page_one.png, shown
## in docs/assess.md): headless Chromium prints the PDF, poppler's pdftoppm draws page one.
report-png: $(STAMP)
	mkdir -p build/report
	$(BIN)/rockmech assess examples/constants/church_geometry.json examples/sites/ntc_site.json \
		--record examples/records/elcentro_NS.dat -o build/report/report.html --pdf
	pdftoppm -r 110 -f 1 -l 1 -png -singlefile build/report/report.pdf docs/img/report_page_one

## The REST service on http://127.0.0.1:8000 (settings: ROCKMECH_* variables; docs/service.md).
serve: $(STAMP)
	$(BIN)/rockmech serve

clean:
	rm -rf $(VENV) out dist build .mypy_cache .ruff_cache .pytest_cache
