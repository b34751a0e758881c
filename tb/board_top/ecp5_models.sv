// Simulation stand-ins for the ECP5 primitives of fpga/ulx3s/ulx3s_top.sv, for
// test_board_top.py::test_shell only. The PLL's outputs are registers the testbench
// clocks (pixel and bit clock at a chosen phase) and its LOCK a register it sets; the
// DDR output register only has to exist: the test reads its D0/D1 inputs, which
// ODDRX1F sends in that order within one SCLK period.
/* verilator lint_off UNUSEDSIGNAL */
module EHXPLLL #(
  parameter string PLLRST_ENA = "", parameter string INTFB_WAKE = "",
  parameter string STDBY_ENABLE = "", parameter string DPHASE_SOURCE = "",
  parameter string OUTDIVIDER_MUXA = "", parameter string OUTDIVIDER_MUXB = "",
  parameter string OUTDIVIDER_MUXC = "", parameter string OUTDIVIDER_MUXD = "",
  parameter int CLKI_DIV = 1, parameter int CLKFB_DIV = 1, parameter string FEEDBK_PATH = "",
  parameter string CLKOP_ENABLE = "", parameter int CLKOP_DIV = 1,
  parameter int CLKOP_CPHASE = 0, parameter int CLKOP_FPHASE = 0,
  parameter string CLKOS_ENABLE = "", parameter int CLKOS_DIV = 1,
  parameter int CLKOS_CPHASE = 0, parameter int CLKOS_FPHASE = 0,
  parameter string CLKOS2_ENABLE = "", parameter int CLKOS2_DIV = 1,
  parameter int CLKOS2_CPHASE = 0, parameter int CLKOS2_FPHASE = 0
) (
  input  logic RST, STDBY, CLKI, CLKFB, PHASESEL0, PHASESEL1, PHASEDIR, PHASESTEP,
  input  logic PHASELOADREG, PLLWAKESYNC, ENCLKOP,
  output logic CLKOP, CLKOS, CLKOS2, CLKINTFB, LOCK
);
  logic clkop_r /* verilator public */;
  logic clkos_r /* verilator public */;
  logic lock_r  /* verilator public */;
  assign CLKOP = clkop_r;
  assign CLKOS = clkos_r;
  assign CLKOS2 = clkos_r;      // not 78.125 MHz: the shell test uses neither the UART nor
                                // span arrays, which are the core clock's only users
  assign CLKINTFB = 1'b0;
  assign LOCK = lock_r;
endmodule

module ODDRX1F (
  input  logic SCLK, RST, D0, D1,
  output logic Q
);
  assign Q = D0;
endmodule

// Bidirectional I/O buffer (the SDRAM's DQ): drives B with I unless T, reads B on O.
module BB (
  input  logic I, T,
  output logic O,
  inout  wire  B
);
  assign B = T ? 1'bz : I;
  assign O = B;
endmodule
/* verilator lint_on UNUSEDSIGNAL */
