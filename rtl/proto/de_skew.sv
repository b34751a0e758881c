// Input delay circuit (Kuijk 1995, 7.6.2): the x-processors add 36-bit numbers as three
// 12-bit blocks with a registered block carry, so block j of an instruction must reach
// a PE j cycles after block 0. This circuit delays block 1 by one and block 2 by two
// clock cycles; the identifier travels with block 0.
`default_nettype none

module de_skew (
  input  logic        clk_i,
  input  logic        rst_i,
  input  logic [11:0] id_i,
  input  logic [35:0] data_i,
  output logic [11:0] id_o,
  output logic [11:0] blk0_o,
  output logic [11:0] blk1_o,
  output logic [11:0] blk2_o
);
  logic [11:0] blk1_q, blk2_q, blk2_q2;

  always_ff @(posedge clk_i) begin
    if (rst_i) begin
      blk1_q  <= 12'd0;
      blk2_q  <= 12'd0;
      blk2_q2 <= 12'd0;
    end else begin
      blk1_q  <= data_i[23:12];
      blk2_q  <= data_i[35:24];
      blk2_q2 <= blk2_q;
    end
  end

  assign id_o    = id_i;
  assign blk0_o  = data_i[11:0];
  assign blk1_o  = blk1_q;
  assign blk2_o  = blk2_q2;
endmodule

`default_nettype wire
