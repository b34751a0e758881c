// Fast simulation (docs/simulation.md, "The fast array"): one repeated piece of a de_array
// cut at the chips' boundary registers = the boundary register of chip c-1 followed by the
// core of chip c. Its bus and pixel inputs reach logic only through registers, so one
// compiled model serves every chip 1..NumChips-1 and its evaluation never depends
// combinationally on what another piece computes in the same cycle.
// Simulation wiring only: every register and gate comes from the RTL modules.
module de_fast_unit
  import de_pkg::*;
#(
  parameter int unsigned NumPe    = 9,
  parameter int unsigned CarryBug = 0
) (
  input  logic             clk_i,
  input  logic             rst_i,
  // chip c-1's core outputs (combinational there), registered here
  input  logic [IdW-1:0]   id_i,
  input  logic [DataW-1:0] data_i,
  input  logic             pix_valid_i,
  input  logic [PixW-1:0]  pix_i,
  input  logic             coll_i,
  // chip c's core outputs
  output logic [IdW-1:0]   id_o,
  output logic [DataW-1:0] data_o,
  output logic             pix_valid_o,
  output logic [PixW-1:0]  pix_o,
  output logic             coll_o,
  output logic             prev_coll_o,  // chip c-1's collision_o (its boundary register)
  input  logic             cfg_mode_i,
  input  logic             cfg_bit_i,
  output logic             cfg_bit_o,
  input  logic             obs_load_i,
  input  logic             obs_shift_i,
  input  logic             obs_bit_i,
  output logic             obs_bit_o
);
  logic [IdW-1:0]   b_id;
  logic [DataW-1:0] b_data;
  logic             b_pixv;
  logic [PixW-1:0]  b_pix;
  /* verilator lint_off UNUSEDSIGNAL */
  logic [NumPe-1:0] bypass;
  /* verilator lint_on UNUSEDSIGNAL */

  de_chip_bound u_bound (
    .clk_i, .rst_i, .id_i, .data_i, .pix_valid_i, .pix_i, .coll_i,
    .id_o(b_id), .data_o(b_data), .pix_valid_o(b_pixv), .pix_o(b_pix), .coll_o(prev_coll_o)
  );

  de_chip_core #(.NumPe(NumPe), .CarryBug(CarryBug)) u_core (
    .clk_i, .rst_i,
    .id_i       (b_id),
    .data_i     (b_data),
    .pix_valid_i(b_pixv),
    .pix_i      (b_pix),
    .id_o, .data_o, .pix_valid_o, .pix_o, .coll_o,
    .cfg_mode_i, .cfg_bit_i, .cfg_bit_o,
    .obs_load_i, .obs_shift_i, .obs_bit_i, .obs_bit_o,
    .bypass_o   (bypass)
  );
endmodule
