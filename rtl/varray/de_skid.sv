// Two-entry skid buffer (valid/ready on both sides): the upstream ready depends only on
// the buffer's own count, so no combinational path runs from ready_i back to ready_o,
// and the downstream data always comes from a register.
`default_nettype none

module de_skid #(
  parameter int unsigned W = 48
) (
  input  logic         clk_i,
  input  logic         rst_i,
  input  logic         valid_i,
  output logic         ready_o,
  input  logic [W-1:0] data_i,
  output logic         valid_o,
  input  logic         ready_i,
  output logic [W-1:0] data_o
);
  logic [1:0]   cnt_d, cnt_q;
  logic [W-1:0] e0_d, e0_q, e1_d, e1_q;
  logic         push, pop;

  assign ready_o = (cnt_q != 2'd2);
  assign valid_o = (cnt_q != 2'd0);
  assign data_o  = e0_q;
  assign push    = valid_i && ready_o;
  assign pop     = valid_o && ready_i;

  always_comb begin
    e0_d  = e0_q;
    e1_d  = e1_q;
    cnt_d = cnt_q + 2'(push) - 2'(pop);
    if (pop) begin
      e0_d = e1_q;
    end
    // The new word goes behind whatever stays.
    if (push && (cnt_q - 2'(pop) == 2'd0)) begin
      e0_d = data_i;
    end
    if (push && (cnt_q - 2'(pop) == 2'd1)) begin
      e1_d = data_i;
    end
  end

  always_ff @(posedge clk_i) begin
    e0_q <= e0_d;
    e1_q <= e1_d;
    if (rst_i) begin
      cnt_q <= '0;
    end else begin
      cnt_q <= cnt_d;
    end
  end
endmodule

`default_nettype wire
