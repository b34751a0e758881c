// UART transmitter of the board top (8N1, LSB first): the loader's replies. The bit
// period is ClkPerBit clocks (de_uart_link derives it and checks its error).
`default_nettype none

module de_uart_tx #(
  parameter int unsigned ClkPerBit = 26  // 78.125 MHz / 3 Mbaud (de_uart_link)
) (
  input  logic       clk_i,
  input  logic       rst_i,
  input  logic       valid_i,
  output logic       ready_o,
  input  logic [7:0] data_i,
  output logic       tx_o
);
  if (ClkPerBit < 1 || ClkPerBit > 65536) begin : g_bad_div
    $fatal(1, "de_uart_tx: ClkPerBit must be 1..65536");
  end

  logic [9:0]  sh_d, sh_q;      // {stop, data, start}, shifted out LSB first
  logic [3:0]  left_d, left_q;  // bits still to send
  logic [15:0] cnt_d, cnt_q;

  always_comb begin
    sh_d   = sh_q;
    left_d = left_q;
    cnt_d  = cnt_q;
    if (left_q == 4'd0) begin
      if (valid_i) begin
        sh_d   = {1'b1, data_i, 1'b0};
        left_d = 4'd10;
        cnt_d  = 16'(ClkPerBit - 1);
      end
    end else if (cnt_q != 16'd0) begin
      cnt_d = cnt_q - 16'd1;
    end else begin
      sh_d   = {1'b1, sh_q[9:1]};
      left_d = left_q - 4'd1;
      cnt_d  = 16'(ClkPerBit - 1);
    end
  end

  always_ff @(posedge clk_i) begin
    if (rst_i) begin
      sh_q   <= 10'h3FF;
      left_q <= 4'd0;
      cnt_q  <= 16'd0;
    end else begin
      sh_q   <= sh_d;
      left_q <= left_d;
      cnt_q  <= cnt_d;
    end
  end

  assign ready_o = (left_q == 4'd0);
  assign tx_o    = sh_q[0];
endmodule

`default_nettype wire
