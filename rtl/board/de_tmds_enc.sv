// TMDS encoder, DVI 1.0 §3.2.2 (8b/10b transition-minimised, DC-balanced), one channel.
//
// While de_i is high the 8-bit pixel is coded in two steps: (1) XOR or XNOR chain,
// whichever gives fewer transitions (q_m[8] says which); (2) the 8 data bits are sent
// inverted or not (q_out[9] says which) so that the running disparity cnt (ones minus
// zeros of everything sent since the last blanking period) is steered back towards 0.
// While de_i is low one of the four control tokens carries c_i = {C1, C0} (on channel 0:
// {VSYNC, HSYNC}) and cnt restarts at 0. sym_o is registered; bit 0 is sent first.
// The testbench model (tb/board_top/tmds.py) is the same algorithm, step by step.
`default_nettype none

module de_tmds_enc (
  input  logic       clk_i,
  input  logic       rst_i,
  input  logic       de_i,
  input  logic [7:0] data_i,
  input  logic [1:0] c_i,
  output logic [9:0] sym_o
);
  logic [8:0]        q_m;
  logic [3:0]        n1_d, n1_qm;
  logic signed [5:0] cnt_d, cnt_q;   // |cnt| <= 8 (docs/board.md §6); 6 bits signed
  logic signed [5:0] diff;           // N1(q_m[7:0]) - N0(q_m[7:0]) = 2*N1 - 8
  logic [9:0]        sym_d, sym_q;

  // Step 1's chain: q[i] = q[i-1] XOR d[i], or XNOR when inv.
  function automatic logic [7:0] chain(logic [7:0] d, logic inv);
    logic [7:0] q;
    q[0] = d[0];
    for (int i = 1; i < 8; i++) q[i] = inv ? ~(q[i-1] ^ d[i]) : (q[i-1] ^ d[i]);
    return q;
  endfunction

  always_comb begin
    n1_d = 4'd0;
    for (int i = 0; i < 8; i++) n1_d = n1_d + 4'(data_i[i]);
    // Step 1: XNOR when that gives fewer transitions (more than four ones, or four with
    // bit 0 clear), else XOR.
    if (n1_d > 4'd4 || (n1_d == 4'd4 && !data_i[0])) begin
      q_m = {1'b0, chain(data_i, 1'b1)};
    end else begin
      q_m = {1'b1, chain(data_i, 1'b0)};
    end
    n1_qm = 4'd0;
    for (int i = 0; i < 8; i++) n1_qm = n1_qm + 4'(q_m[i]);
    diff = $signed({1'b0, n1_qm, 1'b0}) - 6'sd8;   // signed: a disparity

    // Step 2: DC balance.
    sym_d = 10'd0;
    cnt_d = cnt_q;
    if (!de_i) begin
      cnt_d = 6'sd0;
      unique case (c_i)
        2'b00: sym_d = 10'b1101010100;
        2'b01: sym_d = 10'b0010101011;
        2'b10: sym_d = 10'b0101010100;
        default: sym_d = 10'b1010101011;
      endcase
    end else if (cnt_q == 6'sd0 || diff == 6'sd0) begin
      sym_d = {~q_m[8], q_m[8], q_m[8] ? q_m[7:0] : ~q_m[7:0]};
      cnt_d = q_m[8] ? cnt_q + diff : cnt_q - diff;
    end else if ((cnt_q > 6'sd0 && diff > 6'sd0) || (cnt_q < 6'sd0 && diff < 6'sd0)) begin
      sym_d = {1'b1, q_m[8], ~q_m[7:0]};
      cnt_d = cnt_q + (q_m[8] ? 6'sd2 : 6'sd0) - diff;
    end else begin
      sym_d = {1'b0, q_m[8], q_m[7:0]};
      cnt_d = cnt_q - (q_m[8] ? 6'sd0 : 6'sd2) + diff;
    end
  end

  always_ff @(posedge clk_i) begin
    if (rst_i) begin
      cnt_q <= 6'sd0;
      sym_q <= 10'b1101010100;
    end else begin
      cnt_q <= cnt_d;
      sym_q <= sym_d;
    end
  end

  assign sym_o = sym_q;
endmodule

`default_nettype wire
