// The loader's UART link (docs/board.md §3): receiver and transmitter on their own clock
// (clk_uart_i, the board's 78.125 MHz core clock: 26 clocks per bit at 3 Mbaud, 0.16 %
// off), bytes handed to and from the loader's clock (clk_i, the 25 MHz pixel clock,
// where 3 Mbaud would be 8.33 clocks per bit and no integer divider is within 2 %).
//
// Both directions cross with a toggle and a data register that holds still while the
// toggle crosses: a byte takes 10 bit periods on the line, far longer than the three
// flip-flops of a synchroniser in either clock, so no FIFO is needed.
//   RX: each received byte (or framing error) in clk_uart_i loads {ferr, data} and flips
//       rx_tog; clk_i sees the flip through three flip-flops and pulses valid or ferr.
//   TX: the loader's byte is taken when tx_ready_o (no byte in flight), flips tx_req;
//       clk_uart_i starts the transmitter with it and flips tx_ack once the transmitter
//       has taken it; tx_ready_o returns when clk_i sees tx_ack equal tx_req.
// rst_i (clk_i domain) reaches the UART clock through a two-flip-flop synchroniser.
//
// The bit period of both halves is ClkHz / Baud rounded to an integer number of clocks
// (de_uart_pkg); elaboration fails unless it is within 2 % of the exact period
// (docs/board.md §3.1: de_uart_rx samples each bit once, at its middle).
`default_nettype none

module de_uart_link #(
  parameter int unsigned ClkHz = 78_125_000,   // clk_uart_i
  parameter int unsigned Baud  = 3_000_000,
  localparam int unsigned ClkPerBit = de_uart_pkg::clk_per_bit(ClkHz, Baud),
  localparam longint unsigned ErrPm = de_uart_pkg::err_permille(ClkHz, Baud)
) (
  input  logic       clk_i,
  input  logic       rst_i,
  input  logic       clk_uart_i,
  input  logic       rx_i,
  output logic       tx_o,
  // clk_i side, the interface of de_uart_rx / de_uart_tx.
  output logic       rx_valid_o,
  output logic       rx_ferr_o,
  output logic [7:0] rx_data_o,
  input  logic       tx_valid_i,
  output logic       tx_ready_o,
  input  logic [7:0] tx_data_i
);
  if (Baud == 0 || ClkPerBit < 4 || ClkPerBit > 65535) begin : g_bad_div
    $fatal(1, "de_uart_link: ClkHz / Baud must give 4..65535 clocks per bit");
  end
  if (ErrPm >= 20) begin : g_bad_rate
    $fatal(1, "de_uart_link: the integer bit period ClkHz/Baud is off by 2 %% or more, ",
           "so mid-bit sampling would drift out of the bit within one 8N1 frame");
  end

  // Loader-domain TX request: the byte held while its toggle crosses (declared first:
  // both domains use them).
  logic       tx_req_q;
  logic [7:0] tx_hold_q;

  // ------------------------------------------------------------------ UART clock domain
  logic [1:0] urst_q;
  logic       urst;
  always_ff @(posedge clk_uart_i) urst_q <= {urst_q[0], rst_i};
  assign urst = urst_q[1];

  logic       u_valid, u_ferr, u_tx_ready;
  logic [7:0] u_data;

  de_uart_rx #(.ClkPerBit(ClkPerBit)) u_rx (
    .clk_i(clk_uart_i), .rst_i(urst), .rx_i,
    .valid_o(u_valid), .frame_err_o(u_ferr), .data_o(u_data)
  );

  logic       rx_tog_q;
  logic [8:0] rx_hold_q;     // {ferr, data}
  always_ff @(posedge clk_uart_i) begin
    if (urst) begin
      rx_tog_q  <= 1'b0;
      rx_hold_q <= 9'd0;
    end else if (u_valid || u_ferr) begin
      rx_tog_q  <= ~rx_tog_q;
      rx_hold_q <= {u_ferr, u_data};
    end
  end

  // TX request from clk_i: synchronise, start the transmitter, acknowledge.
  logic [2:0] req_sync_q;
  logic       ack_q, u_tx_valid;
  assign u_tx_valid = (req_sync_q[2] != ack_q);
  always_ff @(posedge clk_uart_i) begin
    if (urst) begin
      req_sync_q <= 3'd0;
      ack_q      <= 1'b0;
    end else begin
      req_sync_q <= {req_sync_q[1:0], tx_req_q};
      if (u_tx_valid && u_tx_ready) ack_q <= req_sync_q[2];
    end
  end

  de_uart_tx #(.ClkPerBit(ClkPerBit)) u_tx (
    .clk_i(clk_uart_i), .rst_i(urst), .valid_i(u_tx_valid), .ready_o(u_tx_ready),
    .data_i(tx_hold_q), .tx_o
  );

  // ------------------------------------------------------------------ loader clock domain
  logic [2:0] rx_sync_q;
  logic       rx_seen_q;
  logic [2:0] ack_sync_q;
  logic       rx_valid_q, rx_ferr_q;
  logic [7:0] rx_data_q;
  always_ff @(posedge clk_i) begin
    if (rst_i) begin
      rx_sync_q  <= 3'd0;
      rx_seen_q  <= 1'b0;
      rx_valid_q <= 1'b0;
      rx_ferr_q  <= 1'b0;
      rx_data_q  <= 8'd0;
      ack_sync_q <= 3'd0;
      tx_req_q   <= 1'b0;
      tx_hold_q  <= 8'd0;
    end else begin
      rx_sync_q  <= {rx_sync_q[1:0], rx_tog_q};
      rx_valid_q <= 1'b0;
      rx_ferr_q  <= 1'b0;
      if (rx_sync_q[2] != rx_seen_q) begin
        rx_seen_q  <= rx_sync_q[2];
        rx_valid_q <= ~rx_hold_q[8];
        rx_ferr_q  <= rx_hold_q[8];
        rx_data_q  <= rx_hold_q[7:0];
      end
      ack_sync_q <= {ack_sync_q[1:0], ack_q};
      if (tx_valid_i && tx_ready_o) begin
        tx_req_q  <= ~tx_req_q;
        tx_hold_q <= tx_data_i;
      end
    end
  end
  assign tx_ready_o = (ack_sync_q[2] == tx_req_q);
  assign rx_valid_o = rx_valid_q;
  assign rx_ferr_o  = rx_ferr_q;
  assign rx_data_o  = rx_data_q;
endmodule

`default_nettype wire
