# shadermatrix: `make setup` once (idempotent), then `make demo` / `make test`.
VENV := .venv
PY   := $(VENV)/bin/python

.PHONY: setup demo test lint goldens doctor clean distclean

setup:
	bash scripts/setup.sh

demo: setup
	$(VENV)/bin/shadermatrix build scenes/example.toml --out out/example

# The tests that differ between Python patch releases (the loader on odd bytes, interrupts of a worker pool):
# run again on the second Python that scripts/setup.sh found (.venv-alt), whichever of the two is not .venv's.
ALT_TESTS := tests/lang/test_fuzz.py tests/lang/test_fuzz_regressions.py tests/io/test_hostile_files.py \
             tests/lang/test_hostile_bricks.py tests/lang/test_lang_errors.py tests/lang/test_lang_ext_errors.py \
             tests/library/test_brick_schema.py tests/assemble/test_parallel.py
# the second Python runs the workers' every path but the two longest builds (~165 s), which its other tests repeat
ALT_SKIP := not test_worker_processes_build_what_one_process_builds and not test_kill_9_of_a_parallel_build

test: setup
	$(VENV)/bin/ruff check .
	$(PY) -m pytest -q --durations=15
	@if [ -x .venv-alt/bin/python ]; then \
	  echo "make test: $(ALT_TESTS) on $$(.venv-alt/bin/python -V)"; \
	  .venv-alt/bin/python -m pytest -q -p no:cacheprovider $(ALT_TESTS) -k "$(ALT_SKIP)"; \
	else \
	  echo "make test: no second Python of another version on this machine — ALT_TESTS ran on $$($(PY) -V) only"; \
	fi

lint: setup
	$(VENV)/bin/ruff check .

goldens: setup
	$(PY) -m tests.regen_goldens

.PHONY: reference
reference: setup  # docs/reference/ from the code; tests/project/test_docs_reference.py fails when it is stale
	$(PY) scripts/gen_reference.py docs/reference

doctor: setup
	$(VENV)/bin/shadermatrix doctor

clean:  # build outputs and caches; keeps .venv and .tools
	find out -mindepth 1 ! -name .gitkeep -delete 2>/dev/null || true
	rm -rf build .pytest_cache
	find . -path ./.venv -prune -o -path ./.tools -prune -o -name __pycache__ -type d -exec rm -rf {} +

distclean: clean  # also the Python environment and the locally built tools
	rm -rf $(VENV) .venv-alt .tools
