# Two commands set everything up on a fresh machine and run: `make demo` and `make test`.
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: demo test setup system-deps bench lint

demo: setup
	$(PY) -m robokudo run tabletop --annotated-image robokudo-demo.png

test: setup
	$(PY) -m pytest -q

lint: setup
	$(VENV)/bin/ruff check .

setup: system-deps $(STAMP)

# open3d needs libusb-1.0; graphviz renders trees as SVG; HermiT (ontology reasoning) needs Java.
# Each is installed only when missing.
system-deps:
	@if ! ldconfig -p | grep -q 'libusb-1.0.so.0' || ! command -v dot >/dev/null || ! command -v java >/dev/null; then \
		SUDO=$$( [ "$$(id -u)" = 0 ] && echo "" || echo sudo ); \
		$$SUDO apt-get update -qq && \
		$$SUDO apt-get install -y -qq libusb-1.0-0 graphviz default-jre-headless >/dev/null; \
	fi

$(STAMP): pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -e '.[dev]'
	touch $(STAMP)

bench: setup
	for script in bench/*.py; do $(PY) $$script || exit 1; done
