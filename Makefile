# uvnav — set-up, main job, tests, benchmarks.  Every target creates .venv when missing.
PYTHON ?= python3.11
VENV   ?= .venv
PY     := $(VENV)/bin/python
# Extras installed by `make run` / `make test`; later chapters add theirs here (see docs/design-notes.md).
RUN_EXTRAS  ?= prediction,report,bench,learning,envs,recon,fast,ros,ros2
TEST_EXTRAS ?= prediction,report,bench,learning,envs,recon,fast,ros,ros2,test
# torch is installed before the package (the CPU build is served to pip here; never torchvision)
TORCH_PIN  ?= torch==2.13.0
STAMP_TORCH := $(VENV)/.installed-torch
STAMP_RUN  := $(VENV)/.installed-run
STAMP_TEST := $(VENV)/.installed-test
# peer simulators for benchmarks/peers/ (ir-sim, navground): `make bench` only, never `make test`
STAMP_PEERS := $(VENV)/.installed-peers
BENCH_OUT  ?= benchmarks/results
# Debian's Chromium for the report's browser test (playwright drives it; no browser download)
CHROMIUM   ?= chromium

.PHONY: run test tour fuzz bench peers lint clean venv browser evidence

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

# the README's whole tour on a fresh copy of the tracked files, every command at the quick size
# (tests/test_readme_tour.py; CI runs it after `make test`)
tour: $(STAMP_TEST)
	$(PY) -m pytest -q -s -p no:randomly --tour tests/test_readme_tour.py

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
	$(PY) -m uvnav.experiments.evidence --write docs/evidence.json

# a peer that does not install is not fatal: its script records "available": false
$(STAMP_PEERS): pyproject.toml $(STAMP_RUN) | $(PY)
	@if $(PY) -m pip install --quiet -e ".[peers]"; then touch $@; \
	else echo "note: the peers extra did not install; peer rows read 'no peer'"; fi

peers: $(STAMP_PEERS)

# every benchmark runs (one failing does not stop the others), then the summary table, which
# also replaces the table in benchmarks/README.md; the exit status is 1 when any benchmark failed.
# The release the single and vector envs are compared with (bench_vector_env.py --against), its
# src/ unpacked from git when the repository has the commit (else their rows read "not measured")
BENCH_RELEASE ?= 682d9d2
BENCH_BASE := $(BENCH_OUT)/release-$(BENCH_RELEASE)
BENCH_RUNS = \
	benchmarks/run_benchmarks.py \
	benchmarks/bench_multi.py \
	benchmarks/bench_orca.py \
	benchmarks/bench_ch7.py \
	benchmarks/bench_campaign.py \
	benchmarks/bench_ray.py \
	"benchmarks/bench_vector_env.py $$against" \
	"benchmarks/bench_crowdnav.py --cases 500" \
	"benchmarks/bench_crowdnav.py --cases 500 --law zhang2019-holonomic-v2" \
	"benchmarks/bench_crowdnav.py --cases 500 --law zhang2019-v2" \
	benchmarks/bench_zhang2019_v2.py \
	benchmarks/peers/irsim_steps.py \
	benchmarks/peers/navground_orca.py \
	benchmarks/peers/navground_crowd.py

bench: $(STAMP_RUN) peers
	@mkdir -p $(BENCH_OUT) && touch $(BENCH_OUT)/.sitting; against=; \
	if git cat-file -e "$(BENCH_RELEASE)^{commit}" 2>/dev/null; then \
	  rm -rf $(BENCH_BASE) && mkdir -p $(BENCH_BASE) && \
	  git archive $(BENCH_RELEASE) src | tar -x -C $(BENCH_BASE) && against="--against $(BENCH_BASE)"; \
	else echo "note: commit $(BENCH_RELEASE) is not in this repository: no release to compare with"; fi; \
	status=0; for run in $(BENCH_RUNS); do \
	  echo "== $$run"; $(PY) $$run --out $(BENCH_OUT) || { status=1; echo "FAILED: $$run"; }; \
	done; \
	echo; $(PY) benchmarks/summary.py --results $(BENCH_OUT); \
	$(PY) benchmarks/summary.py --results $(BENCH_OUT) --write-readme benchmarks/README.md; \
	exit $$status

clean:
	rm -rf $(VENV) results report .pytest_cache .mypy_cache .ruff_cache
