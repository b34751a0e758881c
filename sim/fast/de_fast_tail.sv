// Fast simulation (docs/simulation.md, "The fast array"): the tail of a de_array cut at
// the chips' boundary registers = the last chip's boundary register, de_deskew and the
// sticky collision flag, exactly as in rtl/array/de_array.sv.
// Simulation wiring only: every register and gate comes from the RTL modules.
module de_fast_tail
  import de_pkg::*;
(
  input  logic             clk_i,
  input  logic             rst_i,
  input  logic [IdW-1:0]   id_i,          // the last chip's core outputs
  input  logic [DataW-1:0] data_i,
  input  logic             pix_valid_i,
  input  logic [PixW-1:0]  pix_i,
  input  logic             coll_i,
  input  logic             coll_others_i, // OR of chips 0..NumChips-2's collision_o
  output logic [IdW-1:0]   id_o,
  output logic [DataW-1:0] data_o,
  output logic             pix_valid_o,
  output logic [PixW-1:0]  pix_o,
  output logic             pix_collision_o
);
  logic [IdW-1:0]   b_id;
  logic [DataW-1:0] b_data;
  logic             b_coll;

  de_chip_bound u_bound (
    .clk_i, .rst_i, .id_i, .data_i, .pix_valid_i, .pix_i, .coll_i,
    .id_o(b_id), .data_o(b_data), .pix_valid_o(pix_valid_o), .pix_o(pix_o), .coll_o(b_coll)
  );

  de_deskew u_deskew (
    .clk_i, .rst_i,
    .id_i   (b_id),
    .blk0_i (b_data[11:0]),
    .blk1_i (b_data[23:12]),
    .blk2_i (b_data[35:24]),
    .id_o, .data_o
  );

  // The same sticky flag as de_array's coll_q.
  logic coll_d, coll_q;
  assign coll_d = coll_q | coll_others_i | b_coll;
  always_ff @(posedge clk_i) begin
    if (rst_i) coll_q <= 1'b0;
    else       coll_q <= coll_d;
  end
  assign pix_collision_o = coll_q;
endmodule
