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
  logic [IdW-1:0]  ident_q, ident_q2;
  logic [BlkW-1:0] blk0_q, blk0_q2, blk1_q;

  always_ff @(posedge clk_i) begin
    if (rst_i) begin
      ident_q  <= '0;
      ident_q2 <= '0;
      blk0_q   <= '0;
      blk0_q2  <= '0;
      blk1_q   <= '0;
    end else begin
      ident_q  <= id_i;
      ident_q2 <= ident_q;
      blk0_q   <= blk_i[0];
      blk0_q2  <= blk0_q;
      blk1_q   <= blk_i[1];
    end
  end

  assign id_o    = ident_q2;
  assign data_o  = {blk_i[2], blk1_q, blk0_q2};
endmodule

`default_nettype wire
