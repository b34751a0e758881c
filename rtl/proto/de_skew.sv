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
  assign id_o = id_i;

  // Block j of data_i is data_i[j*BlkW +: BlkW], as de_pkg::word_blk selects it.
  for (genvar j = 0; j < NumBlk; j++) begin : g_blk
    de_delay #(.Width(BlkW), .Depth(j)) u_delay (
      .clk_i, .rst_i,
      .d_i(data_i[j*BlkW +: BlkW]),
      .q_o(blk_o[j])
    );
  end
endmodule

`default_nettype wire
