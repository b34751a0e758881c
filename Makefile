# Difference Engine - top-level targets. `make help` lists them.
# Every target sets itself up on first use (scripts/setup.sh: .venv from PyPI).
SHELL := /bin/bash
ROOT := $(abspath .)
VENV := $(ROOT)/.venv
SETUP := $(VENV)/.setup-stamp
ENV := source $(VENV)/env.sh &&
PY := $(VENV)/bin/python
DE := $(VENV)/bin/diffengine
OUT := $(ROOT)/out
DEMO_FILE ?= sw/scenes/fig7_25.cmd

TEST ?= table_7_5
PE ?= 1
BUG ?=
RTL_SRC := $(shell find rtl -name '*.sv' 2>/dev/null | sort)

.PHONY: view gen gen-check test-first-run test-quality sim sim-merge fuzz-hsr help setup demo demo-cmd anim bench-array bench-span fpga-board sim-board postsynth test test-py test-c test-rtl test-long bench bench-hsr clean waves lint fpga

help:
	@echo "make demo        the main job: teapot scene -> HSR -> yproc -> Verilated display"
	@echo "                 controller (3 x 72 chips) and golden model -> out/demo.png, PSNR"
	@echo "                 (SCENE=file.scene CHIPS=72 THREADS=1 RTL=0 for model only;"
	@echo "                 first run builds the model: ~1-1.5 min on 2 cores; the RTL frame ~35 s)"
	@echo "make view        interactive viewer on http://127.0.0.1:PORT/ (default 8765): pick, drag,"
	@echo "                 opacity, light, undo, statistics (SCENE=... default the CAD scene;"
	@echo "                 SCENE=sw/scenes/teapot/teapot_box.scene; docs/viewer.md)"
	@echo "make anim        the shipped animation through incremental frame deltas -> out/anim"
	@echo "make demo-cmd    one command file through the golden model (DEMO_FILE=...)"
	@echo "make test        run every test (sets itself up on first use)"
	@echo "make gen         regenerate the ISA tables from spec/ (gen-check: diff, fail if stale)"
	@echo "make sim         RTL regression vs golden model, HTML/JUnit reports (TIER=smoke|full|nightly J=2)"
	@echo "make sim-merge   join the outputs of make sim SHARD=k/N (sim/out/shard-*) into one report"
	@echo "make test-long   long random regressions (not part of make test)"
	@echo "make test-quality the outlier gate at full size: shipped scenes + public meshes (sw/scenes/meshes)"
	@echo "make bench       golden model speed, y-processor commands per line and host time"
	@echo "                 (docs/performance.md)"
	@echo "make bench-hsr   HSR benchmarks (Fig 5.30, move; Table 5.2, Figs 5.13-5.18) into docs/performance.md"
	@echo "make bench-array Verilated array speed (1/8/72 chips) vs the models"
	@echo "make bench-span  span-serial array: clocks per line on the teapot and CAD frames"
	@echo "make waves TEST=<cocotb test> [PE=p] [BUG=0|1]"
	@echo "                 FST + GTKWave save file for one PE (docs/debugging.md)"
	@echo "make lint        verilator -Wall and verible lint on every RTL file"
	@echo "make fpga        yosys + nextpnr: 9-PE chip on ECP5 and iCE40, 640-PE fit, span-serial"
	@echo "                 array (3 x 648 columns), ULX3S board bitstream (fpga/, docs/fpga.md,"
	@echo "                 docs/board.md)"
	@echo "make fpga-board  only the ULX3S bitstream (fpga/ulx3s)"
	@echo "make sim-board   whole-board full-frame simulations: teapot and CAD frames and 3 animation"
	@echo "                 frames from the SDRAM model through the TMDS encoders, bit-exact vs the"
	@echo "                 golden model, late lines, SDRAM violations -> out/board_sim (docs/board-frames.md;"
	@echo "                 CASES=teapot,cad,anim LOOPS=1 THREADS=1; builds the 72-chip board first:"
	@echo "                 ~2 min, then ~1-1.5 min per case on 2 loaded cores)"
	@echo "make postsynth   yosys netlists simulated in Icarus against the golden model"
	@echo "make fuzz-hsr    coverage-guided libFuzzer run of the sw/hsr fuzz targets (clang)"
	@echo "make setup       create .venv from scripts/requirements.txt"
	@echo "make clean       remove every build product: out/, build/, sim/build, sim/out, sw/hsr/build,"
	@echo "                 sw/yproc/build, sw/fmodel/build, fpga/build, fpga/ulx3s/build (the board's"
	@echo "                 bitstream: 30+ min to redo), fpga/ctrl/out, tb/formal/build, tb/*/sim_build*,"
	@echo "                 the cocotb result XML files (keeps .venv, the ccache and the committed reports)"

setup: $(SETUP)
$(SETUP): scripts/setup.sh scripts/requirements.txt sw/pyproject.toml
	./scripts/ensure_system.sh
	./scripts/setup.sh

# The main job (docs/pipeline.md): RTL=0 skips the Verilated controller.
SCENE ?= sw/scenes/teapot/teapot.scene
CHIPS ?= 72
THREADS ?= 1
RTL ?= 1
demo: $(SETUP)
	@./scripts/ensure_system.sh
	$(ENV) $(DE) demo --scene $(SCENE) --chips $(CHIPS) --threads $(THREADS) \
	  --out $(OUT) $(if $(filter 0,$(RTL)),--no-rtl,)

# The shipped animation through incremental frame deltas (out/anim: PNGs and a GIF).
# ANIMFLAGS: more options of `diffengine anim`, e.g. "--coherent --tol 4" (docs/yproc.md 11).
ANIM ?= sw/scenes/anim/cad_drag.anim
anim: $(SETUP)
	$(ENV) $(DE) anim --anim $(ANIM) --out $(OUT)/anim $(ANIMFLAGS)

# The interactive viewer (docs/viewer.md): SCENE given on the command line, else the CAD scene.
VIEW_SCENE := $(if $(filter command line environment,$(origin SCENE)),$(SCENE),sw/scenes/cad/cad.scene)
PORT ?= 8765
view: $(SETUP)
	@./scripts/ensure_system.sh
	@$(MAKE) -s -C sw/yproc build/yproc
	$(ENV) $(DE) view --scene $(VIEW_SCENE) --port $(PORT)

# One command file through the golden model (the first demo, before the pipeline).
demo-cmd: $(SETUP)
	@mkdir -p $(OUT)
	$(ENV) $(DE) model $(DEMO_FILE) -o $(OUT)/demo_cmd.png
	$(ENV) $(DE) plot $(DEMO_FILE) -o $(OUT)/demo_cmd_scanlines.png
	@echo "demo-cmd: wrote $(OUT)/demo_cmd.png and $(OUT)/demo_cmd_scanlines.png"

# make test = Python model tests + C host tests (if present) + RTL tests (if present).
# The Python and C layers run side by side (the C layer is mostly single-threaded
# compiles), each one's output printed whole when it ends; then the RTL layer.
# yproc is built first: both layers use it, and two makes must not build it at once.
test: $(SETUP)
	@$(MAKE) -s --no-print-directory -j2 -C sw/yproc build/yproc
	@$(MAKE) --no-print-directory -j2 --output-sync=target test-py test-c
	@$(MAKE) --no-print-directory test-rtl

test-py: $(SETUP)
	@./scripts/ensure_system.sh
	$(ENV) cd sw && $(PY) -m pytest -q -n 2 --dist worksteal tests

test-c:
	@./scripts/ensure_system.sh
	$(MAKE) -C sw/hsr test
	$(MAKE) -C sw/yproc test
	$(MAKE) -C sw/fmodel test
	$(MAKE) -C sw/hsr/fuzz smoke

# Coverage-guided libFuzzer run of the sw/hsr fuzz targets (clang; FUZZ_SECONDS each).
fuzz-hsr:
	$(MAKE) -C sw/hsr/fuzz long

# --dist worksteal: an idle worker takes queued tests from the busy one (the long
# benches otherwise leave one core idle at the end).
test-rtl: $(SETUP)
	@./scripts/ensure_system.sh
	@if ls tb/*/test_*.py >/dev/null 2>&1; then $(ENV) cd tb && $(PY) -m pytest -q -n 2 --dist worksteal --durations=12 .; fi

# The RTL regression (docs/regression.md): TIER=smoke|full|nightly, J parallel jobs.
TIER ?= full
J ?= 2
sim: $(SETUP)
	@$(MAKE) -s -C sw/yproc build/yproc
	$(ENV) $(DE) sim --tier $(TIER) -j $(J) $(if $(SHARD),--shard $(SHARD))

# One report and JUnit file from the shards (SHARDS = their folders, CI: the artifacts).
sim-merge: $(SETUP)
	$(ENV) $(DE) sim --merge $(if $(SHARDS),$(abspath $(SHARDS)),$(ROOT)/sim/out/shard-*-of-*)

# The outlier gate (issue 21) at full size: every shipped scene at 640x480 and the public
# meshes with the 69K-triangle bunny (sw/tests/test_meshes.py; make test runs the shipped
# scenes at 320x240 and leaves the bunny out). About 3.5 min on 2 cores.
test-quality: $(SETUP)
	@$(MAKE) -s -C sw/yproc build/yproc
	$(ENV) cd sw && DE_QUALITY_FULL=1 $(PY) -m pytest -q -rA -n $(J) --durations=0 tests/test_meshes.py

# The first-run proof (docs/pipeline.md section 4): removes liblz4-dev, then concurrent
# set-up callers must all succeed and bring it back. Alone, never inside make test.
test-first-run: $(SETUP)
	$(ENV) cd tb && DE_TEST_REINSTALL=1 $(PY) -m pytest -q -s tools/test_system_packages.py

# 10^7 random commands per array configuration through the RTL (hours on 2 cores).
# J parallel workers (default 2); each configuration prints its seed (-rP shows it).
test-long: $(SETUP)
	$(ENV) cd tb && N_COMMANDS=10000000 $(PY) -m pytest -v -rP -n $(J) --durations=0 \
	  de_array/test_de_array_scoreboard.py

waves: $(SETUP)
	@./scripts/ensure_fst.sh
	$(ENV) $(PY) scripts/waves.py $(TEST) --pe $(PE) $(if $(BUG),--bug $(BUG),)

lint: $(SETUP)
	$(ENV) ./scripts/lint.sh

# The ISA tables of every language from spec/*.toml (de_pkg.sv, de_isa.h, isa/_tables.py).
gen gen-check: $(SETUP)
	$(ENV) cd sw && $(PY) -m diffengine.isa.gen $(if $(filter gen-check,$@),--check)

fpga: $(SETUP)
	$(MAKE) -C fpga all

bench-hsr: $(SETUP)
	$(ENV) $(DE) bench hsr --write $(BENCH_ARGS)
	$(ENV) $(DE) bench table52 --write

bench: $(SETUP)
	$(ENV) $(DE) bench model --write
	$(ENV) $(DE) bench model --fast --write
	$(ENV) $(DE) bench yproc --write

# QUICK=1: the 72-chip rates (and the baseline's, when built) and the stream only.
bench-array: $(SETUP)
	$(ENV) $(DE) bench array --write $(if $(filter 1,$(QUICK)),--quick,)

bench-span: $(SETUP)
	$(ENV) $(DE) bench span --write

fpga-board: $(SETUP)
	$(MAKE) -C fpga/ulx3s

# The whole-board full-frame simulations (docs/board-frames.md): sim/board/board_sim.py.
CASES ?= teapot,cad,anim
LOOPS ?= 1
sim-board: $(SETUP)
	$(ENV) $(PY) sim/board/board_sim.py --cases $(CASES) --loops $(LOOPS) --threads $(THREADS) \
	  --out $(OUT)/board_sim

postsynth: $(SETUP)
	$(MAKE) -C fpga postsynth

clean:
	rm -rf $(OUT) build sim/out sim/build sw/hsr/build sw/yproc/build sw/fmodel/build fpga/build
	rm -rf fpga/ulx3s/build fpga/ctrl/out tb/formal/build
	find tb -name 'sim_build*' -prune -exec rm -rf {} +
	find tb -name '*.result.xml' -delete
	rm -f tb/de_array/coverage_*.txt tb/de_array/seed_*.txt
	git worktree prune 2>/dev/null || true
