# cosim: every target sets up .venv first (idempotent), so a fresh clone needs only `make demo` / `make test`.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
SCENARIO ?= warehouse-random
OUT    ?= runs/demo
ARGS   ?=

STUDIES := runs/studies
STUDY = $(BIN)/cosim study studies/$(1).toml --out $(STUDIES)/$(1) --resume

.PHONY: setup ns3 demo test test-fast docs lint bench bench-peers clean help reproduce study-comm study-comm-reduced \
	study-burst study-scale study-paper study-nav study-mapping study-mapping-reduced \
	study-mapping-acceptance study-mapping-defaults study-mapping-drift map-aces map-fr079 \
	lab-real lab-mixed study-humans study-humans-reduced study-humans-contacts study-traffic \
	study-local-replanning study-local-replanning-network study-radio rl train-agent study-agents

help:  ## list the targets
	@grep -E '^[a-z-]+:.*##' $(MAKEFILE_LIST) | sed 's/:.*## /\t/'

$(STAMP): pyproject.toml
	@$(PYTHON) -c 'import sys; assert sys.version_info >= (3, 11), "cosim needs Python >= 3.11, found " + sys.version.split()[0]'
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	$(BIN)/python -m cosim.runner.warmup
	touch $(STAMP)

# the warm-up compiles the numba kernels once (about 20 s) into their cache (__pycache__ next
# to each module), so that the first `make demo` shows the real speed
setup: $(STAMP)  ## create .venv, install cosim with its dev tools, compile the numba kernels

# ns-3's Python bindings for network.backend = "ns3" (the `ns3` extra): `make test` runs the
# radio for real, so it installs them (cppyy is built from source: about 2 min, 600 MB)
NS3_STAMP := $(VENV)/.installed-ns3
$(NS3_STAMP): $(STAMP)
	$(BIN)/python -m pip install --quiet -e '.[dev,ns3]'
	touch $(NS3_STAMP)

ns3: $(NS3_STAMP)  ## install the ns3 extra (network.backend = "ns3") into .venv

# the learning tutorial's trainer (the `rl` extra: Stable-Baselines3 and PyTorch); `make test`
# does not install it (its tests of a trained model are skipped without it)
RL_STAMP := $(VENV)/.installed-rl
$(RL_STAMP): $(STAMP)
	$(BIN)/python -m pip install --quiet -e '.[dev,rl]'
	touch $(RL_STAMP)

rl: $(RL_STAMP)  ## install the rl extra (Stable-Baselines3, PyTorch) into .venv

# ARGS: more arguments of the run of demo, lab-real and lab-mixed (ARGS='--seed 3 --duration-s 30')
demo: setup  ## run the default scenario and say where the results are
	$(BIN)/cosim run $(SCENARIO) --out $(OUT) --force $(ARGS)

test: setup ns3 docs  ## the documentation build and the whole test suite, on every core (CI runs this)
	$(BIN)/python -m pytest -q -n auto

test-fast: setup  ## all but the slow tests (whole runs, SUMO, DDS, Dask, real time), on every core
	$(BIN)/python -m pytest -q -n auto -m "not slow"

DOCS_ENV := NO_MKDOCS_2_WARNING=1 DISABLE_MKDOCS_2_WARNING=true
docs: setup  ## the documentation site -> site/index.html (strict: a broken reference fails the build)
	$(DOCS_ENV) $(BIN)/mkdocs build --strict --quiet
	@echo "documentation: site/index.html"

lint: setup  ## ruff and mypy --strict
	$(BIN)/ruff check cosim models adapters studies tests bench examples docs
	$(BIN)/mypy cosim models adapters examples/labkit/labkit

bench: setup  ## benchmarks -> bench/results.json
	$(BIN)/python bench/run.py --out bench/results.json

PEERS := bench/peers/.venv
$(PEERS)/.installed: bench/peers/requirements.txt
	$(PYTHON) -m venv $(PEERS)
	$(PEERS)/bin/python -m pip install --quiet -r bench/peers/requirements.txt
	touch $@

bench-peers: setup $(PEERS)/.installed  ## cosim beside IR-SIM-X (its own venv) on the 50-robot hall -> bench/results.json
	$(BIN)/python bench/run.py --out bench/results.json --only peers

reproduce: setup  ## Scenarios 1-3, reduced comm sweep, map sharing and people (about 8 min on 2 cores)
	$(call STUDY,paper)
	$(BIN)/cosim run warehouse-random --figures --force --quiet --out runs/paper-scenario1-random
	$(BIN)/cosim run warehouse-rows --figures --force --quiet --out runs/paper-scenario1-racks
	$(call STUDY,comm_sweep_reduced)
	$(call STUDY,map_sharing_reduced)
	$(call STUDY,humans_reduced)
	$(MAKE) --no-print-directory lab-real lab-mixed
	@echo "reports: $(STUDIES)/paper/report.md $(STUDIES)/comm_sweep_reduced/report.md $(STUDIES)/map_sharing_reduced/report.md $(STUDIES)/humans_reduced/report.md"
	@echo "scenario 1: runs/paper-scenario1-random/figures runs/paper-scenario1-racks/figures"
	@echo "mixed reality: runs/lab-real-in-virtual/figures runs/lab-mixed/figures"

lab-real: setup  ## Scenario 2: a stand-in physical robot through goals among virtual obstacles (1 min, real time)
	$(BIN)/cosim run lab-real-in-virtual --standin --figures --force --out runs/lab-real-in-virtual $(ARGS)

lab-mixed: setup  ## Scenario 3: a stand-in physical robot and 3 virtual ones share tasks (1 min, real time)
	$(BIN)/cosim run lab-mixed --standin --figures --force --out runs/lab-mixed $(ARGS)

study-comm: setup  ## the full comm sweep: 1,080 runs (about 30 min on 2 cores)
	$(call STUDY,comm_sweep)

study-comm-reduced: setup  ## the comm sweep reduced to 81 runs
	$(call STUDY,comm_sweep_reduced)

study-burst: setup  ## Gilbert-Elliott vs Bernoulli loss at equal mean loss
	$(call STUDY,burst_vs_iid)

study-scale: setup  ## 4 to 1,000 robots: wall time, real-time factor, wall per robot-second (log-log), 3 seeds x 60 s
	$(call STUDY,scale)

study-paper: setup  ## the paper's Scenario 1, random shelves and racks
	$(call STUDY,paper)

study-mapping: setup  ## map sharing: bandwidth x loss x share mode, 5 seeds x 300 s (about 20 min)
	$(call STUDY,map_sharing)

study-mapping-reduced: setup  ## map sharing reduced to 12 runs x 120 s
	$(call STUDY,map_sharing_reduced)

study-mapping-acceptance: setup  ## the warehouse mapping acceptance: 10 seeds x 300 s, matching vs odometry (about 3 min)
	$(call STUDY,mapping_acceptance)

study-mapping-defaults: setup  ## warehouse-random with only mapping on and drift 0.02, 10 seeds x 120 s, robots layer auto vs off (under 1 min)
	$(call STUDY,mapping_defaults)

study-traffic: setup  ## traffic policies 'none', 'lanes', 'pibt' x 25/50 robots, 10 seeds x 300 s (about 7 min)
	$(call STUDY,traffic)

study-local-replanning: setup  ## every controller x planner on warehouse-humans, 0 and 10 workers, 8 seeds x 120 s (about 6 min)
	$(call STUDY,local_replanning)

study-radio: setup ns3  ## the built-in network model against an ns-3 radio, 4/20/50 robots x few/many shelves, 2 seeds x 60 s
	$(call STUDY,radio)

train-agent: rl  ## the learning tutorial: PPO on cosim/Warehouse-v0, 400k steps in 8 environments (about 10 min) -> studies/policies, studies/results/agents_training
	$(BIN)/python studies/train_agent.py --steps 400000

study-agents: rl  ## the learnt policy against cosim's navigation and a random policy in the lab room, 8 seeds x 60 s
	$(call STUDY,agents)

study-local-replanning-network: setup  ## dwa and orca in the lab room over network latency and loss, 4 seeds x 120 s (about 2 min)
	$(call STUDY,local_replanning_network)

study-humans: setup  ## robots among 0-20 SUMO-driven workers, 5 seeds x 300 s (about 3 min)
	$(call STUDY,humans)

study-humans-reduced: setup  ## robots among 0 or 10 workers, 2 seeds x 60 s
	$(call STUDY,humans_reduced)

study-humans-contacts: setup  ## do people walk into robots? 5 cases, 37 runs (about 3 min)
	$(BIN)/python studies/humans_contacts.py --json studies/results/humans_contacts/runs_new.json

ACES ?= ../shared/data/aces_lidar
FR079 ?= ../shared/data/fr079_lidar
map-aces: setup  ## map the ACES building's recording (needs ../shared/data) into runs/aces
	$(BIN)/cosim map $(ACES) --out runs/aces --reference /ground_truth --force

study-mapping-drift: setup  ## mapping on 10 drift realizations of each shared building, as recorded and cut to a 10 m lidar, with and without loop closure (about 3 min)
	$(BIN)/python studies/mapping_drift.py --seeds 10 --workers 2

map-fr079: setup  ## map Freiburg building 079's recording (needs ../shared/data) into runs/fr079
	$(BIN)/cosim map $(FR079) --out runs/fr079 --reference /ground_truth --force

study-nav: setup  ## navigation acceptance: 3 presets x 10 seeds x 300 s
	$(BIN)/python studies/nav_acceptance.py --seeds 10 --duration-s 300 --workers 2

clean:  ## remove the virtual environment, caches and run outputs
	rm -rf $(VENV) runs site .pytest_cache .mypy_cache .ruff_cache build *.egg-info
	find . -name __pycache__ -type d -prune -exec rm -rf {} +
