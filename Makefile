# fieldkit — every target works on a fresh machine: it creates .venv and installs first.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: demo test test-all test-rstone bench bench-diagnose lint video video-hard clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	$(BIN)/python -c "from fieldkit.model.compile_cache import main; main()"
	touch $(STAMP)

## The whole loop on the bundled Tornado Mountain survey in under a minute: reduce ->
## diagnose -> fit -> simulate -> export; out/demo/index.md links every figure and report.
demo: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python examples/demo.py out/demo

## Fast test suite (a few minutes on 2 cores).
test: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python -m pytest -q -n auto

## Everything, including tests marked slow.
test-all: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python -m pytest -q -n auto -m ''

## The real r.stone on fieldkit's exports (tests/export/test_rstone_real.py, slow):
## needs GRASS GIS and r.stone (tools/r.stone/install.sh), skipped with the reason
## otherwise; about 15 s.
test-rstone: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python -m pytest -q -p no:xdist -m '' tests/export/test_rstone_real.py

## Speed and memory figures (printed, not asserted); bench_diagnose_power runs its
## short setting here (a few tables per condition, ~3 min on 2 cores), and
## bench_campaign_power its short grid of virtual campaigns (1 and 3 paths of 20
## and 50 scars, a few campaigns per cell). bench_3d runs PlatRock's ThreeD engine
## beside fieldkit's 3-D simulator: its first run creates PlatRock's own venv in
## .bench/platrock-venv (a few minutes; needs libgdal-dev for gdal-config; skipped
## with the reason when pip cannot reach the index or GDAL is missing).
bench: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python benchmarks/run_all.py

## The measured run of diagnose's power and false-finding rates: on clean tables
## (>= 100 tables per target condition; about an hour on 2 idle cores), then on
## virtual campaigns through the reduction (the done-when rows with >= 100
## campaigns, then the grid of 1/3/10 paths x 20/50/100 scars x trees; hours).
bench-diagnose: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python benchmarks/bench_diagnose_power.py --full
	MPLBACKEND=Agg $(BIN)/python benchmarks/bench_campaign_power.py --full

## Re-render the synthetic high-speed clips in video/ (deterministic).
video: $(STAMP)
	$(BIN)/python video/render.py

## Render the hard synthetic clips (video/hard.py; not committed) into video/hard/.
video-hard: $(STAMP)
	$(BIN)/python video/render.py --out video/hard hard

lint: $(STAMP)
	$(BIN)/ruff check fieldkit tests benchmarks examples

clean:
	rm -rf $(VENV) .bench out .pytest_cache
