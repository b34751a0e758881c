"""RTL drivers: running the Verilated SystemVerilog from Python and looking inside it.
`harness` builds and runs the plain C++ array harness (sim/harness), `dc_harness` the
full-colour display controller (sim/dc); `trace` is `diffengine trace` (per-PE state per
cycle from the RTL or the structural model, breakpoints, first difference), and
`inspect_page` is `diffengine inspect` (one frame as a self-contained HTML page). Python
never sits in the clock loop: the harnesses are C++, these modules drive them.
"""
