// Fast simulation (docs/simulation.md, "The fast array"): a de_array with the same
// parameters and ports as rtl/array/de_array.sv whose chips run in the composed C++ model
// of sim/fast/de_fast.cpp (one compiled chip model called once per chip). Every output
// of de_array is a register, so this shell calls the model once per rising edge with the
// inputs of the ending cycle and registers what it returns: cycle for cycle the same
// ports. Built instead of rtl/array/de_array.sv by the fast harness builds only
// (sim/Makefile, sim/dc/Makefile with FAST=1); sim/fast/equiv.cpp checks the two against
// each other every cycle.
`default_nettype none

module de_array
  import de_pkg::*;
#(
  parameter int unsigned NumChips  = 72,
  parameter int unsigned CarryBug  = 0,
  parameter int unsigned NumPe     = 9,
  parameter logic [1023:0] FaultMask = '0,
  // The pieces are built without the timing-only copies (de_chip TimingCopies = 0).
  parameter int unsigned TimingCopies = 0,
  // de_chip InReg: the composed model has one clock per PE position (InReg = 0) only.
  parameter int unsigned InReg = 0
) (
  input  logic             clk_i,
  input  logic             rst_i,
  input  logic [IdW-1:0]   id_i,
  input  logic [DataW-1:0] data_i,
  output logic [IdW-1:0]   id_o,
  output logic [DataW-1:0] data_o,
  output logic             pix_valid_o,
  output logic [PixW-1:0]  pix_o,
  output logic [15:0]      n_pe_o,
  output logic             pix_collision_o,
  input  logic             cfg_mode_i,
  input  logic             cfg_bit_i,
  output logic             cfg_bit_o,
  input  logic             obs_load_i,
  input  logic             obs_shift_i,
  output logic             obs_bit_o
);
  import "DPI-C" function chandle de_fast_new(input int num_chips, input int num_pe,
                                              input int carry_bug, input string scope);
  import "DPI-C" function void de_fast_step(
    input chandle h, input bit rst, input int ident, input longint data,
    input bit cfg_mode, input bit cfg_bit, input bit obs_load, input bit obs_shift,
    output int id_o, output longint data_o, output bit pixv_o, output int pix_o,
    output bit coll_o, output bit cfg_bit_o, output bit obs_bit_o);

  if (FaultMask != '0) begin : g_bad_fault_mask
    $fatal(1, "de_array (sim/fast): FaultMask is a test of the flat RTL only");
  end
  if (InReg != 0) begin : g_bad_in_reg
    $fatal(1, "de_array (sim/fast): InReg = 1 is built from the flat RTL only");
  end

  chandle h;
  initial h = de_fast_new(NumChips, NumPe, CarryBug, $sformatf("%m"));

  // The DPI carries fixed C types; only the low IdW/PixW/DataW bits are the array's.
  /* verilator lint_off UNUSEDSIGNAL */
  int          s_id, s_pix;
  longint      s_data;
  /* verilator lint_on UNUSEDSIGNAL */
  bit          s_pixv, s_coll, s_cfg, s_obs;

  // Every output of de_array is a register: the model's answer, taken at the edge.
  always @(posedge clk_i) begin
    de_fast_step(h, rst_i, 32'(id_i), 64'(data_i), cfg_mode_i, cfg_bit_i, obs_load_i,
                 obs_shift_i, s_id, s_data, s_pixv, s_pix, s_coll, s_cfg, s_obs);
    id_o            <= IdW'(s_id);
    data_o          <= DataW'(s_data);
    pix_valid_o     <= s_pixv;
    pix_o           <= PixW'(s_pix);
    pix_collision_o <= s_coll;
    cfg_bit_o       <= s_cfg;
    obs_bit_o       <= s_obs;
  end
  assign n_pe_o = 16'(NumChips * NumPe);
endmodule

`default_nettype wire
