# The RTL file lists from the FuseSoC cores, for Makefiles (docs/simulation.md, "File
# lists"). Set CORES to the lists needed, each <core>.<target> (core: the last part of
# diffengine:de:<core>), then include this file; each list is then the variable
# CORE_<core>.<target> (absolute paths, dependencies first), e.g.
#   CORES := array.sim fast.shell
#   include $(ROOT)/scripts/cores.mk
#   ... $(CORE_array.sim) ...
# Each list is a make fragment build/cores/<core>.<target>.mk that scripts/filelist.py
# writes; make remakes it (and re-reads it) only when a .core file or filelist.py is newer,
# so an up-to-date build does not start FuseSoC.
CORES_BUILD := $(ROOT)/build/cores
CORE_DEFS := $(wildcard $(ROOT)/rtl/*/*.core $(ROOT)/sim/*/*.core $(ROOT)/fpga/*.core \
  $(ROOT)/tb/*/*.core)
include $(foreach c,$(CORES),$(CORES_BUILD)/$(c).mk)
$(CORES_BUILD)/%.mk: $(CORE_DEFS) $(ROOT)/scripts/filelist.py
	@$(ROOT)/.venv/bin/python $(ROOT)/scripts/filelist.py $(subst ., ,$*) --make CORE_$* -o $@
