# Two commands set everything up on a fresh machine and run: `make demo` and `make test`.
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
KERNELS_CHECKED := $(VENV)/.kernels-checked

.PHONY: demo test setup system-deps bench bench-all lint

demo: setup
	$(PY) -m robokudo run tabletop --annotated-image robokudo-demo.png
	$(PY) -m robokudo query --explain "find milk in fridge"

test: setup
	$(PY) -m pytest -q

lint: setup
	$(VENV)/bin/ruff check .

setup: system-deps $(STAMP) $(KERNELS_CHECKED)

# numba checks a cached compiled kernel against its own module's file only: a kernel that calls a kernel of another
# module keeps the old compiled code after that module changes. So when any annotator source is newer than the last
# check, every cached kernel is dropped (they compile again on first use).
$(KERNELS_CHECKED): $(wildcard annotators/*/*.py)
	@find annotators -path '*/__pycache__/*' \( -name '*.nbi' -o -name '*.nbc' \) -delete
	@mkdir -p $(VENV) && touch $@

# open3d needs libusb-1.0; graphviz renders trees as SVG; HermiT (ontology reasoning) needs Java; the live view's
# browser test drives Debian's headless Chromium. Each is installed only when missing.
system-deps:
	@if ! ldconfig -p | grep -q 'libusb-1.0.so.0' || ! command -v dot >/dev/null || ! command -v java >/dev/null \
		|| ! command -v chromium >/dev/null || ! command -v chromedriver >/dev/null; then \
		SUDO=$$( [ "$$(id -u)" = 0 ] && echo "" || echo sudo ); \
		$$SUDO apt-get update -qq && \
		$$SUDO apt-get install -y -qq libusb-1.0-0 graphviz default-jre-headless chromium chromium-driver >/dev/null; \
	fi

# rapidocr-onnxruntime (OCR, models inside its wheel) requires opencv-python, which would clash with
# opencv-python-headless: it is installed without its requirements, which pyproject.toml lists instead.
# mediapipe (human pose; its pose model ships in the wheel) likewise: it pins numpy<2, protobuf<5 and
# opencv-contrib-python, but its legacy pose solution runs with our numpy, protobuf and headless OpenCV.
$(STAMP): pyproject.toml Makefile
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -e '.[dev]'
	$(PY) -m pip install -q --no-deps 'rapidocr-onnxruntime==1.4.4'
	$(PY) -m pip install -q --no-deps 'mediapipe==0.10.21'
	$(PY) -m pip uninstall -q -y opencv-python 2>/dev/null || true
	touch $(STAMP)

# The benchmarks of issue 19 (belief store, planning, tick overhead): each prints its goals with met / NOT met; the
# output goes to bench/output/ and the goal lines are summed up at the end (a script that fails counts as NOT met).
# The make fails when a goal is not met. `make bench-all` runs every script in bench/.
BENCH_GOALS := bench/bench_beliefs.py bench/bench_planning.py bench/bench_tick_overhead.py

bench: setup
	@mkdir -p bench/output
	@for script in $(BENCH_GOALS); do \
		name=$$(basename $$script .py); echo "== $$script"; \
		{ $(PY) $$script || echo "goal: $$script runs to the end: NOT met (exit $$?)"; } 2>&1 | tee bench/output/$$name.txt; \
	done
	@echo "== goals of issue 19"
	@for script in $(BENCH_GOALS); do \
		name=$$(basename $$script .py); \
		grep -E '(^|[^A-Za-z])(met|NOT met)([^A-Za-z]|$$)' bench/output/$$name.txt | sed "s|^|$$name: |"; \
	done
	@! grep -qE 'NOT met' $(patsubst bench/%.py,bench/output/%.txt,$(BENCH_GOALS))

bench-all: setup
	for script in bench/*.py; do $(PY) $$script || exit 1; done
