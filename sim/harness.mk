# Included by sim/Makefile and sim/dc/Makefile (after ROOT and CHIPS): what both Verilator
# harness builds share - the configuration defaults, ccache, threads, the C++ include
# paths and the shared helper header.
CARRY_BUG ?= 0
THREADS ?= 1
FLAT ?= 0
CCACHE := $(shell command -v ccache 2>/dev/null)
# ccache hashes paths relative to the checkout, so another clone on this machine hits.
export CCACHE_BASEDIR ?= $(ROOT)
THREAD_FLAGS := $(if $(filter-out 1,$(THREADS)),--threads $(THREADS),)
# sw/include: the generated ISA header; sim/include: the harnesses' C++ helpers.
HARNESS_H := $(ROOT)/sim/include/de_verilated.h
HARNESS_INC := -I$(ROOT)/sw/include -I$(ROOT)/sim/include
