# uvnav — set-up, main job, tests, benchmarks.  Every target creates .venv when missing.
PYTHON ?= python3.11
VENV   ?= .venv
PY     := $(VENV)/bin/python
# Extras installed by `make run` / `make test`; later chapters add theirs here (see docs/design-notes.md).
RUN_EXTRAS  ?= prediction,report,bench,learning,envs,recon,fast
TEST_EXTRAS ?= prediction,report,bench,learning,envs,recon,fast,test
# torch is installed before the package (the CPU build is served to pip here; never torchvision)
TORCH_PIN  ?= torch==2.13.0
STAMP_TORCH := $(VENV)/.installed-torch
STAMP_RUN  := $(VENV)/.installed-run
STAMP_TEST := $(VENV)/.installed-test
# Debian's Chromium for the report's browser test (playwright drives it; no browser download)
CHROMIUM   ?= chromium

.PHONY: run test fuzz bench lint clean venv browser evidence

$(PY):
	$(PYTHON) -m venv $(VENV) || python3 -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip setuptools wheel

$(STAMP_TORCH): | $(PY)
	$(PY) -m pip install --quiet "$(TORCH_PIN)"
	touch $@

$(STAMP_RUN): pyproject.toml $(STAMP_TORCH) | $(PY)
	$(PY) -m pip install --quiet -e ".[$(RUN_EXTRAS)]"
	touch $@

$(STAMP_TEST): pyproject.toml $(STAMP_TORCH) | $(PY)
	$(PY) -m pip install --quiet -e ".[$(TEST_EXTRAS)]"
	touch $@

venv: $(STAMP_TEST)

browser:
	@command -v $(CHROMIUM) >/dev/null 2>&1 || { \
	  if [ "$$(id -u)" = 0 ]; then apt-get update -qq && apt-get install -y -qq $(CHROMIUM) >/dev/null; \
	  else echo "note: install Debian's '$(CHROMIUM)' package for the browser test"; fi; }

run: $(STAMP_RUN)
	$(VENV)/bin/uvnav run

test: $(STAMP_TEST) browser
	$(PY) -m pytest -n 2 -q --hypothesis-profile=ci

# fresh random hypothesis examples (not derandomised, more of them): looks for new counter-examples
fuzz: $(STAMP_TEST)
	$(PY) -m pytest -n 2 -q --hypothesis-profile=fuzz -m "not slow" tests

lint: $(STAMP_TEST)
	$(VENV)/bin/ruff check src tests benchmarks
	$(VENV)/bin/ruff format --check src tests benchmarks
	$(VENV)/bin/mypy
	$(VENV)/bin/lint-imports

# every measured figure quoted in docs/thesis-notes.md, regenerated (both sizes) into the record
evidence: $(STAMP_RUN)
	$(PY) -m uvnav.bench.evidence --write docs/evidence.json

bench: $(STAMP_RUN)
	$(PY) benchmarks/run_benchmarks.py --out benchmarks/results
	$(PY) benchmarks/bench_multi.py --out benchmarks/results
	$(PY) benchmarks/bench_orca.py --out benchmarks/results
	$(PY) benchmarks/bench_ch7.py --out benchmarks/results
	$(PY) benchmarks/bench_campaign.py --out benchmarks/results
	$(PY) benchmarks/bench_packed.py --out benchmarks/results
	$(PY) benchmarks/bench_crowdnav.py --cases 500 --out benchmarks/results
	$(PY) benchmarks/bench_crowdnav.py --cases 500 --law zhang2019-holonomic-v2 --out benchmarks/results
	$(PY) benchmarks/bench_crowdnav.py --cases 500 --law zhang2019-v2 --out benchmarks/results
	$(PY) benchmarks/bench_zhang2019_v2.py --out benchmarks/results

clean:
	rm -rf $(VENV) results report .pytest_cache .mypy_cache .ruff_cache
