// Output delay circuit (Kuijk 1995, 7.6.2, Fig. 7.17): realigns the skewed 36-bit bus
// that leaves the last PE, so that a chained array or a logic analyser sees whole
// words again. Block 0 (and the identifier) wait two cycles, block 1 one cycle.
`default_nettype none

module de_deskew
  import de_pkg::*;
(
  input  logic                         clk_i,
  input  logic                         rst_i,
  input  logic [IdW-1:0]               id_i,
  input  logic [NumBlk-1:0][BlkW-1:0]  blk_i,   // block j j clocks late (de_skew's)
  output logic [IdW-1:0]               id_o,
  output logic [DataW-1:0]             data_o
);
  // The identifier travels with block 0: both wait for the last block.
  de_delay #(.Width(IdW), .Depth(NumBlk - 1)) u_id (.clk_i, .rst_i, .d_i(id_i), .q_o(id_o));

  for (genvar j = 0; j < NumBlk; j++) begin : g_blk
    de_delay #(.Width(BlkW), .Depth(NumBlk - 1 - j)) u_delay (
      .clk_i, .rst_i,
      .d_i(blk_i[j]),
      .q_o(data_o[j*BlkW +: BlkW])
    );
  end
endmodule

`default_nettype wire
