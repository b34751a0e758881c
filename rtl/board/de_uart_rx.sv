// UART receiver of the board top (8N1, LSB first), docs/board.md §3.
//
// The bit period is ClkPerBit clocks; de_uart_link derives it from its clock and baud
// rate and refuses to elaborate unless it is within 2 % of the exact period, because the
// receiver samples every bit once, at its middle, and an 8N1 frame tolerates about 5 % of
// total rate mismatch between the two ends (half a bit over 9.5 bits), which the host's
// own baud-rate error must share.
//
// The line is synchronised by two flip-flops. A falling edge starts a start bit; if the
// line returns to 1 at any clock of the start bit's first half, it was a glitch and the
// receiver goes back to idle (start-bit glitch rejection). Every bit is then sampled at
// its middle, ClkPerBit clocks apart. A stop bit that reads 0 is a framing error: the
// byte is not delivered, frame_err_o pulses for one clock, and the receiver waits for
// the line to return to idle (1) before it looks for the next start bit, so a break or
// a wrong baud rate yields errors, not garbage bytes.
`default_nettype none

module de_uart_rx #(
  parameter int unsigned ClkPerBit = 26  // 78.125 MHz / 3 Mbaud (de_uart_link)
) (
  input  logic       clk_i,
  input  logic       rst_i,
  input  logic       rx_i,
  output logic       valid_o,      // one clock per received byte
  output logic       frame_err_o,  // one clock per framing error
  output logic [7:0] data_o
);
  if (ClkPerBit < 4 || ClkPerBit > 65535) begin : g_bad_div
    $fatal(1, "de_uart_rx: ClkPerBit must be 4..65535 (half a bit to reject a glitch)");
  end

  typedef enum logic [2:0] {SIdle, SStart, SData, SStop, SBreak} state_e;

  state_e      state_d, state_q;
  logic [15:0] cnt_d, cnt_q;
  logic [2:0]  bit_d, bit_q;
  logic [7:0]  sh_d, sh_q;
  logic        rx_q, rx_q2;
  logic        valid_d, valid_q, ferr_d, ferr_q;

  always_comb begin
    state_d = state_q;
    cnt_d   = cnt_q;
    bit_d   = bit_q;
    sh_d    = sh_q;
    valid_d = 1'b0;
    ferr_d  = 1'b0;
    unique case (state_q)
      SIdle: begin
        if (!rx_q2) begin
          state_d = SStart;
          cnt_d   = 16'(ClkPerBit / 2 - 1);
        end
      end
      SStart: begin
        if (rx_q2) begin
          state_d = SIdle;   // back to 1 before the middle of the start bit: a glitch
        end else if (cnt_q != 16'd0) begin
          cnt_d = cnt_q - 16'd1;
        end else begin
          // Low for the whole first half of the start bit: a real start bit.
          state_d = SData;
          cnt_d   = 16'(ClkPerBit - 1);
          bit_d   = 3'd0;
        end
      end
      SData: begin
        if (cnt_q != 16'd0) begin
          cnt_d = cnt_q - 16'd1;
        end else begin
          sh_d  = {rx_q2, sh_q[7:1]};
          cnt_d = 16'(ClkPerBit - 1);
          bit_d = bit_q + 3'd1;
          if (bit_q == 3'd7) state_d = SStop;
        end
      end
      SStop: begin
        if (cnt_q != 16'd0) begin
          cnt_d = cnt_q - 16'd1;
        end else if (rx_q2) begin
          valid_d = 1'b1;
          state_d = SIdle;
        end else begin
          ferr_d  = 1'b1;
          state_d = SBreak;
        end
      end
      SBreak: begin
        if (rx_q2) state_d = SIdle;
      end
      default: state_d = SIdle;
    endcase
  end

  always_ff @(posedge clk_i) begin
    if (rst_i) begin
      rx_q    <= 1'b1;
      rx_q2   <= 1'b1;
      state_q <= SIdle;
      cnt_q   <= 16'd0;
      bit_q   <= 3'd0;
      sh_q    <= 8'd0;
      valid_q <= 1'b0;
      ferr_q  <= 1'b0;
    end else begin
      rx_q    <= rx_i;
      rx_q2   <= rx_q;
      state_q <= state_d;
      cnt_q   <= cnt_d;
      bit_q   <= bit_d;
      sh_q    <= sh_d;
      valid_q <= valid_d;
      ferr_q  <= ferr_d;
    end
  end

  assign valid_o     = valid_q;
  assign data_o      = sh_q;
  assign frame_err_o = ferr_q;
endmodule

`default_nettype wire
