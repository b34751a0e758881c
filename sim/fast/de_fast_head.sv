// Fast simulation (docs/simulation.md, "The fast array"): the head of a de_array cut at
// the chips' boundary registers. de_skew feeds chip 0's core directly, exactly as in
// rtl/array/de_array.sv; chip 0's boundary register lives in the next piece.
// Simulation wiring only: every register and gate comes from the RTL modules.
`default_nettype none

module de_fast_head
  import de_pkg::*;
#(
  parameter int unsigned NumPe    = 9,
  parameter int unsigned CarryBug = 0
) (
  // de_array's inputs, as de_sim::drive (sim/include/de_verilated.h) names them
  input  logic             clk_i,
  input  logic             rst_i,
  input  logic [IdW-1:0]   id_i,
  input  logic [DataW-1:0] data_i,
  input  logic             cfg_mode_i,
  input  logic             cfg_bit_i,
  input  logic             obs_load_i,
  input  logic             obs_shift_i,
  // chip 0's core outputs
  output link_t            link_o,
  output chain_t           chain_o
);
  link_t skew_link;  // chip 0's input: the skewed bus, no pixel
  /* verilator lint_off UNUSEDSIGNAL */
  logic [NumPe-1:0] bypass;
  /* verilator lint_on UNUSEDSIGNAL */

  de_skew u_skew (.clk_i, .rst_i, .id_i, .data_i, .id_o(skew_link.id), .blk_o(skew_link.data));
  assign {skew_link.pix_valid, skew_link.pix, skew_link.coll} = '0;
  // As in de_array: chip 0's zero test of block 1, registered beside de_skew.
  logic skew_blk1z_q;
  always_ff @(posedge clk_i) begin
    if (rst_i) skew_blk1z_q <= 1'b1;
    else       skew_blk1z_q <= (data_i[BlkW +: BlkW] == '0);
  end

  de_chip_core #(.NumPe(NumPe), .CarryBug(CarryBug), .TimingCopies(0)) u_core (
    .clk_i, .rst_i, .link_o, .chain_o,
    .link_i     (skew_link),
    .blk1z_i    (skew_blk1z_q),
    .idsel_i    (skew_link.id),   // as in de_array: chip 0's copy is the input itself
    .chain_ctl_i({cfg_mode_i, obs_load_i, obs_shift_i}),
    .chain_i    ({cfg_bit_i, 1'b0}),
    .bypass_o   (bypass)
  );
endmodule

`default_nettype wire
