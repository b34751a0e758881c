// Fast simulation (docs/simulation.md, "The fast array"): the tail of a de_array cut at
// the chips' boundary registers = the last chip's boundary register, de_deskew and the
// sticky collision flag, exactly as in rtl/array/de_array.sv.
// Simulation wiring only: every register and gate comes from the RTL modules.
`default_nettype none

module de_fast_tail
  import de_pkg::*;
(
  input  logic             clk_i,
  input  logic             rst_i,
  input  link_t            link_i,          // the last chip's core outputs
  input  logic             coll_others_i,   // OR of chips 0..NumChips-2's collision flags
  // de_array's outputs
  output logic [IdW-1:0]   id_o,
  output logic [DataW-1:0] data_o,
  output logic             pix_valid_o,
  output logic [PixW-1:0]  pix_o,
  output logic             pix_collision_o
);
  link_t b_link;
  /* verilator lint_off UNUSEDSIGNAL */
  logic  b_blk1z;  // timing only, for a next chip's PE 0: there is none
  logic [IdW-1:0] b_idsel;  // likewise
  /* verilator lint_on UNUSEDSIGNAL */

  // No identifier copy: the pieces are built as de_chip with TimingCopies = 0, and so is
  // the trace build's flat de_array (sim/Makefile), whose fast-forward copies every
  // register of its last boundary here by name.
  de_chip_bound #(.IdCopy(0)) u_bound (.clk_i, .rst_i, .link_i, .link_o(b_link),
                                       .blk1z_o(b_blk1z), .idsel_o(b_idsel));

  de_deskew u_deskew (
    .clk_i, .rst_i,
    .id_i (b_link.id), .blk_i(b_link.data), .id_o, .data_o
  );
  assign pix_valid_o = b_link.pix_valid;
  assign pix_o       = b_link.pix;

  // The same sticky flag as de_array's coll_q.
  logic coll_d, coll_q;
  assign coll_d = coll_q | coll_others_i | b_link.coll;
  always_ff @(posedge clk_i) begin
    if (rst_i) coll_q <= 1'b0;
    else       coll_q <= coll_d;
  end
  assign pix_collision_o = coll_q;
endmodule

`default_nettype wire
