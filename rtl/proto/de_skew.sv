// Input delay circuit (Kuijk 1995, 7.6.2): the x-processors add 36-bit numbers as three
// 12-bit blocks with a registered block carry, so block j of an instruction must reach
// a PE j cycles after block 0. This circuit delays block 1 by one and block 2 by two
// clock cycles; the identifier travels with block 0.
`default_nettype none

module de_skew
  import de_pkg::*;
(
  input  logic                         clk_i,
  input  logic                         rst_i,
  input  logic [IdW-1:0]               id_i,
  input  logic [DataW-1:0]             data_i,
  output logic [IdW-1:0]               id_o,
  output logic [NumBlk-1:0][BlkW-1:0]  blk_o    // block j delayed by j clocks
);
  // Block j of data_i is data_i[j*BlkW +: BlkW], as de_pkg::word_blk selects it; written
  // as slices, since calling word_blk mapped de_array to a different (equivalent) netlist.
  logic [BlkW-1:0] blk1_q, blk2_q, blk2_q2;

  always_ff @(posedge clk_i) begin
    if (rst_i) begin
      blk1_q  <= '0;
      blk2_q  <= '0;
      blk2_q2 <= '0;
    end else begin
      blk1_q  <= data_i[1*BlkW +: BlkW];
      blk2_q  <= data_i[2*BlkW +: BlkW];
      blk2_q2 <= blk2_q;
    end
  end

  assign id_o  = id_i;
  assign blk_o = {blk2_q2, blk1_q, data_i[0 +: BlkW]};
endmodule

`default_nettype wire
