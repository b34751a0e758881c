// Fast simulation (docs/simulation.md, "The fast array"): the head of a de_array cut at
// the chips' boundary registers. de_skew feeds chip 0's core directly, exactly as in
// rtl/array/de_array.sv; chip 0's boundary register lives in the next piece.
// Simulation wiring only: every register and gate comes from the RTL modules.
module de_fast_head
  import de_pkg::*;
#(
  parameter int unsigned NumPe    = 9,
  parameter int unsigned CarryBug = 0
) (
  input  logic             clk_i,
  input  logic             rst_i,
  input  logic [IdW-1:0]   id_i,
  input  logic [DataW-1:0] data_i,
  output logic [IdW-1:0]   id_o,
  output logic [DataW-1:0] data_o,
  output logic             pix_valid_o,
  output logic [PixW-1:0]  pix_o,
  output logic             coll_o,
  input  logic             cfg_mode_i,
  input  logic             cfg_bit_i,
  output logic             cfg_bit_o,
  input  logic             obs_load_i,
  input  logic             obs_shift_i,
  output logic             obs_bit_o
);
  logic [11:0] skew_id, skew_b0, skew_b1, skew_b2;
  /* verilator lint_off UNUSEDSIGNAL */
  logic [NumPe-1:0] bypass;
  /* verilator lint_on UNUSEDSIGNAL */

  de_skew u_skew (
    .clk_i, .rst_i, .id_i, .data_i,
    .id_o(skew_id), .blk0_o(skew_b0), .blk1_o(skew_b1), .blk2_o(skew_b2)
  );

  de_chip_core #(.NumPe(NumPe), .CarryBug(CarryBug)) u_core (
    .clk_i, .rst_i,
    .id_i       (skew_id),
    .data_i     ({skew_b2, skew_b1, skew_b0}),
    .pix_valid_i(1'b0),
    .pix_i      ('0),
    .id_o, .data_o, .pix_valid_o, .pix_o, .coll_o,
    .cfg_mode_i, .cfg_bit_i, .cfg_bit_o,
    .obs_load_i, .obs_shift_i,
    .obs_bit_i  (1'b0),
    .obs_bit_o,
    .bypass_o   (bypass)
  );
endmodule
