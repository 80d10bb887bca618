# shadermatrix: `make setup` once (idempotent), then `make demo` / `make test`.
VENV := .venv
PY   := $(VENV)/bin/python

.PHONY: setup demo test goldens doctor clean distclean

setup:
	bash scripts/setup.sh

demo: setup
	$(VENV)/bin/shadermatrix build scenes/example.toml --out out/example

test: setup
	$(PY) -m pytest -q

goldens: setup
	$(PY) -m tests.regen_goldens

doctor: setup
	$(VENV)/bin/shadermatrix doctor

clean:  # build outputs and caches; keeps .venv and .tools
	find out -mindepth 1 ! -name .gitkeep -delete 2>/dev/null || true
	rm -rf build .pytest_cache
	find . -path ./.venv -prune -o -path ./.tools -prune -o -name __pycache__ -type d -exec rm -rf {} +

distclean: clean  # also the Python environment and the locally built tools
	rm -rf $(VENV) .tools
