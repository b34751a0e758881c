// A delay line of Depth registers (Depth = 0: a wire), reset to zero. The skewed bus
// is built from it (de_skew, de_deskew): block j of a word runs j clocks behind block 0,
// so each block is this primitive with its own Depth.
`default_nettype none

module de_delay #(
  parameter int unsigned Width = 1,
  parameter int unsigned Depth = 1
) (
  input  logic             clk_i,
  input  logic             rst_i,
  input  logic [Width-1:0] d_i,
  output logic [Width-1:0] q_o     // d_i of Depth clocks ago
);
  if (Width < 1) begin : g_bad_width
    $fatal(1, "de_delay: Width must be >= 1");
  end

  if (Depth == 0) begin : g_wire
    assign q_o = d_i;
    // No register: the clock and the reset go unused (block 0 of de_skew, for one).
    /* verilator lint_off UNUSEDSIGNAL */
    logic unused_clk_rst;
    assign unused_clk_rst = ^{clk_i, rst_i};
    /* verilator lint_on UNUSEDSIGNAL */
  end else begin : g_regs
    // stage_q[0] is the newest, stage_q[Depth-1] the output.
    logic [Depth-1:0][Width-1:0] stage_d, stage_q;

    if (Depth == 1) begin : g_one
      assign stage_d = d_i;
    end else begin : g_shift
      assign stage_d = {stage_q[Depth-2:0], d_i};
    end

    always_ff @(posedge clk_i) begin
      if (rst_i) begin
        stage_q <= '0;
      end else begin
        stage_q <= stage_d;
      end
    end

    assign q_o = stage_q[Depth-1];
  end
endmodule

`default_nettype wire
