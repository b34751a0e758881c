# Included by sim/Makefile and sim/dc/Makefile: what a build needs to use the fast array
# (docs/simulation.md, "The fast array") in place of rtl/array/de_array.sv.
#   $(FAST_SHELL)  the de_array shell to Verilate instead of rtl/array/de_array.sv
#   $(FAST_CPP)    the composed model and its DPI functions
#   $(FAST_LIBS)   the three Verilated pieces (built by the fast-pieces target)
#   $(FAST_VFLAGS) include paths and the compiled NumPe/CarryBug for $(FAST_CPP)
# The pieces depend only on the chip RTL and CARRY_BUG, so every array size and the
# display controller share one set (sim/build/fast_b<CARRY_BUG>).
# FAST_PUBLIC=1: the pieces with their registers public (sim/fast/public_regs.vlt), for the
# trace build's fast-forward (docs/simulation.md 7.5), in their own folder.
FAST_PUBLIC ?= 0
# FAST_PGO=0: pieces without the profile-guided second compile (sim/fast/pieces.mk); the
# public variant is never trained (it only fast-forwards trace builds).
FAST_PGO ?= 1
FAST_DIR := $(ROOT)/sim/build/fast_b$(CARRY_BUG)$(if $(filter 1,$(FAST_PUBLIC)),_pub,)
FAST_SHELL := $(ROOT)/sim/fast/de_array.sv
FAST_CPP := $(ROOT)/sim/fast/de_fast.cpp
FAST_LIBS := $(foreach p,head unit tail,$(FAST_DIR)/$(p)/Vde_fast_$(p)__ALL.a)
FAST_VFLAGS := -CFLAGS "-I$(FAST_DIR)/head -I$(FAST_DIR)/unit -I$(FAST_DIR)/tail \
  -I$(ROOT)/sim/fast -I$(ROOT)/sim/include -I$(ROOT)/sw/include -DDE_FAST_NUM_PE=9 -DDE_FAST_CARRY_BUG=$(CARRY_BUG)" \
  $(if $(FAST_LDFLAGS),-LDFLAGS "$(FAST_LDFLAGS)",)

# Always asks the pieces' own make (cheap when they are up to date), under a lock.
fast-pieces:
	@mkdir -p $(ROOT)/sim/build
	@flock $(FAST_DIR).lock $(MAKE) -s -j 3 -f $(ROOT)/sim/fast/pieces.mk \
	  FASTDIR=$(FAST_DIR) CARRY_BUG=$(CARRY_BUG) FAST_PGO=$(if $(filter 1,$(FAST_PUBLIC)),0,$(FAST_PGO)) \
	  VEXTRA="$(if $(filter 1,$(FAST_PUBLIC)),$(ROOT)/sim/fast/public_regs.vlt,)"

