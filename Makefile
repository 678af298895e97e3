# Two commands do all set-up on a fresh machine:
#   make demo   Abdulla & Hadi (2025) scenario 2, its moving obstacles, planned by GWO, driven with replan (log, video, plot)
#   make test   run the test suite
# Each creates .venv and installs swarmnav into it on first use.

PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
DEMO_SCENARIO ?= gwo-scenario-2
DEMO_PLANNER ?= gwo
DEMO_NAVIGATOR ?= replan
export MUJOCO_GL ?= egl

STUDIES ?= $(shell $(BIN)/swarmnav studies --json 2>/dev/null | $(BIN)/python -c "import json,sys; print(' '.join(s['name'] for s in json.load(sys.stdin)))")

.PHONY: demo test bench bench-barn-all install clean studies readme-table rerun-stale typing-path docs

$(STAMP): pyproject.toml Makefile planners/_colony_walk.c planners/_grid_search.c planners/_dstar_lite.c
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	@echo "installing swarmnav into $(VENV) (pip's output: $(VENV)/install.log)"
	@$(BIN)/python -m pip install --quiet --upgrade pip > $(VENV)/install.log 2>&1 || (cat $(VENV)/install.log; exit 1)
	@$(BIN)/python -m pip install --quiet -e '.[test,bench,rl]' >> $(VENV)/install.log 2>&1 || (cat $(VENV)/install.log; exit 1)
	@$(MAKE) --no-print-directory typing-path
	@touch $(STAMP)

# The editable install maps swarmnav, swarmnav.sim, ... to their folders with an import hook, which type checkers
# do not run: mypy would not find swarmnav at all. A folder of symbolic links, $(VENV)/typing/swarmnav (the files
# of sim/api/ and a link per folder of pyproject.toml's package-dir, so a module added later is there too), put on
# the path by a static .pth file, is the package as a wheel lays it out, py.typed included.
TYPING_TREE := $(CURDIR)/$(VENV)/typing
typing-path:
	@rm -rf $(TYPING_TREE) && mkdir -p $(TYPING_TREE)/swarmnav
	@for f in sim/api/*.py sim/api/py.typed; do ln -s $(CURDIR)/$$f $(TYPING_TREE)/swarmnav/; done
	@$(BIN)/python -c "import os, sys, tomllib; folders = tomllib.load(open('pyproject.toml', 'rb'))['tool']['setuptools']['package-dir']; [os.symlink(os.path.abspath(folder), os.path.join(sys.argv[1], name.split('.', 1)[1])) for name, folder in folders.items() if name != 'swarmnav']" $(TYPING_TREE)/swarmnav
	@$(BIN)/python -c "import sys, sysconfig; open(sysconfig.get_paths()['purelib'] + '/swarmnav_typing.pth', 'w').write(sys.argv[1] + '\n')" $(TYPING_TREE)

install: $(STAMP)

demo: $(STAMP)
	@mkdir -p logs
	$(BIN)/swarmnav run $(DEMO_SCENARIO) --planner $(DEMO_PLANNER) --navigator $(DEMO_NAVIGATOR) --seed 0 \
		--out logs/demo.mcap --overwrite --video logs/demo.mp4 --json-out logs/demo.json
	@$(BIN)/swarmnav plot logs/demo.mcap -o logs/demo.png > /dev/null
	@echo "plot: logs/demo.png   (inspect the log: swarmnav log info logs/demo.mcap; open it in Foxglove)"

# the suite on TEST_WORKERS processes, each taking whole files (module fixtures stay in one process)
TEST_WORKERS ?= 2
test: $(STAMP)
	$(BIN)/python -m pytest -q -n $(TEST_WORKERS) --dist loadfile

# The documentation site (mkdocs.yml, docs/): built with --strict into site/, then served on
# http://127.0.0.1:$(DOCS_PORT) (rebuilt as pages change; Ctrl-C stops it).
DOCS_PORT ?= 8000
docs: $(STAMP)
	NO_MKDOCS_2_WARNING=1 $(BIN)/python -m mkdocs build --strict -d site
	NO_MKDOCS_2_WARNING=1 $(BIN)/python -m mkdocs serve --strict -a 127.0.0.1:$(DOCS_PORT)

# Every benchmark; `make bench BENCH_FLAGS=--quick` runs each in under a minute.
BENCH_FLAGS ?=
bench: $(STAMP)
	$(BIN)/swarmnav bench sim $(BENCH_FLAGS)
	$(BIN)/swarmnav bench planners $(BENCH_FLAGS)
	$(BIN)/swarmnav bench grid $(BENCH_FLAGS)
	$(BIN)/swarmnav bench render $(BENCH_FLAGS)
	$(BIN)/swarmnav bench env $(BENCH_FLAGS)
	$(BIN)/swarmnav bench navigation $(BENCH_FLAGS)
	$(BIN)/swarmnav bench study $(BENCH_FLAGS)
	$(BIN)/swarmnav bench cli $(BENCH_FLAGS)
	$(BIN)/swarmnav bench odometry $(BENCH_FLAGS)

# BARN's speed line (issue 34): all 300 BARN worlds x every online navigator in its BARN configuration
# (models/suites/barn-navigators.toml), one run each, on 2 workers; the target is 60 minutes of wall time on
# 2 cores. The rows go to logs/barn-all.json (`python -m swarmnav.benchmarks.barn_table` reads such files),
# the wall time to the last line.
bench-barn-all: $(STAMP)
	mkdir -p logs
	start=$$(date +%s); $(BIN)/swarmnav bench navigation --suite barn --barn-runs 1 \
		--arms models/suites/barn-navigators.toml --by-scenario --workers 2 --json > logs/barn-all.json && \
	echo "bench-barn-all: $$(( $$(date +%s) - start )) s of wall time for 300 BARN worlds x every configuration (target 3600 s on 2 cores)"

# Every bundled study into studies/<name>/ (rows resume if interrupted), with report.html and report.md.
# Quick by default (each study's quick_seeds, about 10 min on 2 cores); `make studies STUDY_RUN=` runs them in full
# (about 40 min) into the same folders, resuming the quick rows.
STUDY_RUN ?= --quick
studies: $(STAMP)
	for s in $(STUDIES); do \
		$(BIN)/swarmnav study $$s $(STUDY_RUN) --out studies/$$s && $(BIN)/swarmnav report studies/$$s || exit 1; \
	done

# The generated tables (the marker blocks; the README moved into docs/): the claims table of
# docs/reference/studies.md (each bundled study with [[claims]] run in full into a fresh
# studies/readme-table/<name>/, its verdicts copied to models/studies/results/<name>/claims.json, committed,
# and the table regenerated from them); the navigation tables of docs/navigation.md and the headline table of
# README.md and docs/results.md from the committed `bench navigation --json` results (models/suites/results/);
# the BARN and CrowdNav tables of docs/barn.md and docs/crowds.md.
CLAIM_STUDIES ?= $(shell $(BIN)/swarmnav studies --json 2>/dev/null | $(BIN)/python -c "import json,sys; print(' '.join(s['name'] for s in json.load(sys.stdin) if s['claims']))")
# Each study runs only the arms its claims compare (--claims-only), on every seed of the study file (the seed
# rule's count); CLAIMS_RUN=--quick runs the quick seeds instead (not for committing: their verdicts are
# underpowered).  `make rerun-stale` reruns exactly the studies whose committed claims.json is stale.
CLAIMS_RUN ?=
readme-table: $(STAMP)
	for s in $(CLAIM_STUDIES); do \
		rm -rf studies/readme-table/$$s; \
		$(BIN)/swarmnav study $$s --claims-only $(CLAIMS_RUN) --out studies/readme-table/$$s && \
		$(BIN)/swarmnav report studies/readme-table/$$s && mkdir -p models/studies/results/$$s && \
		cp studies/readme-table/$$s/claims.json models/studies/results/$$s/claims.json || exit 1; \
	done
	$(BIN)/swarmnav report --readme-table models/studies/results --readme docs/reference/studies.md
	for r in dyn300 dyn300-rangefinder dyn; do $(BIN)/python -m swarmnav.benchmarks.navigation_table models/suites/results/$$r.json --readme docs/navigation.md || exit 1; done
	for page in README.md docs/results.md; do $(BIN)/python -m swarmnav.benchmarks.navigation_table models/suites/results/dyn300.json --readme $$page || exit 1; done
	$(BIN)/python -m swarmnav.benchmarks.barn_table --readme docs/barn.md
	$(BIN)/python -m swarmnav.benchmarks.crowd_table models/suites/results/crowdnav.json --readme docs/crowds.md

rerun-stale: $(STAMP)
	$(MAKE) readme-table CLAIM_STUDIES="$$($(BIN)/swarmnav report --check-fresh models/studies/results --names)"

clean:
	rm -rf $(VENV) build site *.egg-info
