// Board top of the Difference Engine prototype, portable core (docs/board.md).
//
//   uart_rx_i -> de_uart_link -> de_loader --X/F/Q--> de_sdram_frames <-> sd_* (SDRAM)
//   uart_tx_o <- de_uart_link <-+                     | players R/G/B
//                                                     v
//                                              display_controller (3 arrays, NumBuf 1)
//                                                     |
//   tmds_o[2:0] <- de_tmds_enc x 3 <- rgb8_o / hsync_o / vsync_o / blank_o
//
// The pixel clock (clk_i), plus clk_core_i for the UART (always: 3 Mbaud needs a clock
// with an integer bit period, de_uart_link) and for the span-serial arrays when
// SpanArray = 1 (9 * NumChips columns each in block RAM, docs/fpga.md 3), plus
// clk_sdram_i (125 MHz) for the SDRAM controller and the frame fetchers. The board shell
// (fpga/ulx3s/) adds the PLL, the 10:1 serialisers, the SDRAM clock and the pins. The
// frames live in SDRAM as tables of lines (docs/sdram-frames-spec.md); per colour a
// fetcher, a 2,048-word dual-clock prefetch FIFO, a player and an instruction buffer
// (the display controller's one-buffer-per-colour choice, docs/display-controller.md
// §9.1); each player is the single y-processor of its colour. TMDS channel 0 is blue
// and carries {VSYNC, HSYNC} as {C1, C0} while blanking, channel 1 green, channel 2 red
// (DVI 1.0 §3.1).
`default_nettype none

module de_board_core #(
  parameter int unsigned NumChips    = 1,      // chips of 9 PEs per colour array
  parameter int unsigned CarryBug    = 0,
  parameter int unsigned PfDepth     = 2048,   // prefetch FIFO words per colour
  parameter int unsigned SdTckPs     = 8000,   // clk_sdram_i period (125 MHz)
  parameter int unsigned SdTinitNs   = 100_000,  // SDRAM power-up wait (tests shorten it)
  parameter int unsigned UartClkHz   = 78_125_000,  // UART on clk_core_i (de_uart_link)
  parameter int unsigned Baud        = 3_000_000,   // FT231X maximum; divider 26, 0.16 %
  parameter int unsigned TimeoutBits = 22,
  parameter int unsigned BufDepth    = 16,
  parameter int unsigned MaxLines    = 512,
  parameter de_pkg::video_mode_t TestMode = de_pkg::VideoTestDefault,  // mode_i = 3
  parameter int unsigned SpanArray   = 0,      // 1: span-serial arrays on clk_core_i
  parameter int unsigned SpanLatency = 300,    // their Refresh -> column 0, pixel clocks
  // Their pixel -> core FIFO, log2 slots: 2,048 slots hold the CAD scene's paced backlog
  // (698 slots in make bench-span; 256 overflowed and lost 6 pixels a frame, docs/board-frames.md).
  parameter int unsigned SpanFifoAw  = 11
) (
  input  logic            clk_i,
  input  logic            clk_core_i,
  input  logic            clk_sdram_i,  // 125 MHz: the PLL's CLKOP (the TMDS bit clock)
  input  logic            rst_i,
  input  logic [1:0]      mode_i,       // video mode (display-controller.md §3), in reset
  input  logic            uart_rx_i,
  output logic            uart_tx_o,
  output logic [2:0][9:0] tmds_o,       // [0] blue + sync, [1] green, [2] red; bit 0 first
  // Status (LEDs) and, for simulation and debugging, the pixels before encoding.
  output logic [7:0]      led_o,
  output logic [2:0][7:0] rgb8_o,       // [0] R, [1] G, [2] B
  output logic            hsync_o,
  output logic            vsync_o,
  output logic            blank_o,
  // SDRAM (clk_sdram_i; docs/sdram-frames-spec.md §4): DQ split for the I/O buffer.
  output de_sdram_pkg::sdram_out_t sd_o,
  input  logic [15:0]     sd_dq_i
);
  localparam int unsigned NumCh = 3;

  // ------------------------------------------------------------------ UART + loader
  logic        rx_valid, rx_ferr, tx_valid, tx_ready;
  logic [7:0]  rx_data, tx_data;
  logic [2:0]  pix_collision;
  logic [15:0] ferr_count, chk_count, cmd_count;
  logic [2:0]  out8_shift;
  logic        out8_sat, align_err, pending, frame, sd_cmd_valid, sd_cmd_ready;
  logic [56:0] sd_cmd;
  logic [7:0]  malformed, late_words;
  logic [13:0] reg_addr;
  logic [31:0] reg_rdata;

  de_uart_link #(.ClkHz(UartClkHz), .Baud(Baud)) u_uart (
    .clk_i, .rst_i, .clk_uart_i(clk_core_i), .rx_i(uart_rx_i), .tx_o(uart_tx_o),
    .rx_valid_o(rx_valid), .rx_ferr_o(rx_ferr), .rx_data_o(rx_data),
    .tx_valid_i(tx_valid), .tx_ready_o(tx_ready), .tx_data_i(tx_data)
  );

  de_loader #(
    .NumChips(NumChips), .TimeoutBits(TimeoutBits)
  ) u_loader (
    .clk_i, .rst_i,
    .rx_valid_i     (rx_valid),
    .rx_data_i      (rx_data),
    .rx_ferr_i      (rx_ferr),
    .tx_valid_o     (tx_valid),
    .tx_ready_i     (tx_ready),
    .tx_data_o      (tx_data),
    .sd_cmd_valid_o (sd_cmd_valid),
    .sd_cmd_ready_i (sd_cmd_ready),
    .sd_cmd_o       (sd_cmd),
    .out8_shift_o   (out8_shift),
    .out8_sat_o     (out8_sat),
    .reg_addr_o     (reg_addr),
    .reg_rdata_i    (reg_rdata),
    .frame_i        (frame),
    .pending_i      (pending),
    .align_err_i    (align_err),
    .pix_collision_i(pix_collision),
    .malformed_i    (malformed),
    .late_i         (late_words),
    .rx_ferr_count_o(ferr_count),
    .chk_err_count_o(chk_count),
    .cmd_err_count_o(cmd_count)
  );

  // ------------------------------------------------------------------ SDRAM frame store
  // The mode's active lines: de_pkg's table (spec/video.toml) for the fixed modes, read
  // into constants (no logic), and the test mode's parameter; the case is the only mux
  // (a mux of whole modes, TestMode or de_pkg::video_mode(mode_i), mapped the board to
  // a different netlist).
  localparam de_pkg::video_mode_t Mode0 = de_pkg::video_mode(2'd0);
  localparam de_pkg::video_mode_t Mode1 = de_pkg::video_mode(2'd1);
  localparam de_pkg::video_mode_t Mode2 = de_pkg::video_mode(2'd2);
  logic [11:0] vactive;
  always_comb begin
    unique case (mode_i)
      2'd0:    vactive = Mode0.v_act;
      2'd1:    vactive = Mode1.v_act;
      2'd2:    vactive = Mode2.v_act;
      default: vactive = TestMode.v_act;
    endcase
  end

  logic [NumCh-1:0][0:0]       wr_valid, wr_ready;
  logic [NumCh-1:0][0:0][47:0] wr_data;

  /* verilator lint_off UNUSEDSIGNAL */  // init done: for waveforms and debugging only
  logic sd_init_done;
  /* verilator lint_on UNUSEDSIGNAL */
  logic [NumCh-1:0]       fr_valid, fr_ready, dc_late;
  logic [NumCh-1:0][47:0] fr_data;

  de_sdram_frames #(
    .PfDepth(PfDepth), .SdTckPs(SdTckPs), .SdTinitNs(SdTinitNs)
  ) u_frames (
    .clk_i, .rst_i, .clk_sdram_i,
    .vactive_i     (vactive),
    .cmd_valid_i   (sd_cmd_valid),
    .cmd_ready_o   (sd_cmd_ready),
    .cmd_i         (sd_cmd),
    .wr_valid_o    (fr_valid),
    .wr_ready_i    (fr_ready),
    .wr_data_o     (fr_data),
    .dc_late_i     (dc_late),
    .frame_o       (frame),
    .q_pending_o   (pending),
    .malformed_o   (malformed),
    .late_o        (late_words),
    .sd_init_done_o(sd_init_done),
    .sd_o, .sd_dq_i
  );
  // ------------------------------------------------------------------ display controller
  /* verilator lint_off UNUSEDSIGNAL */
  logic [11:0]            line;
  logic                   window;
  logic [NumCh-1:0][0:0]  done, late;
  logic [NumCh-1:0][11:0] rgb12;
  logic [NumCh-1:0]       cfg_bit_o, obs_bit_o;
  /* verilator lint_on UNUSEDSIGNAL */

  display_controller #(
    .NumChips   (NumChips),
    .CarryBug   (CarryBug),
    .NumBuf     (1),
    .BufDepth   (BufDepth),
    .NumBins    (16),
    .BinShift   (7),
    .MaxLines   (MaxLines),
    .TestMode   (TestMode),
    .SpanArray  (SpanArray),
    .SpanLatency(SpanLatency),
    .SpanFifoAw (SpanFifoAw)
  ) u_dc (
    .clk_i, .rst_i, .clk_core_i, .mode_i,
    .wr_valid_i     (wr_valid),
    .wr_ready_o     (wr_ready),
    .wr_data_i      (wr_data),
    .line_o         (line),
    .window_o       (window),
    .done_o         (done),
    .late_o         (late),
    .reg_addr_i     (reg_addr),
    .reg_rdata_o    (reg_rdata),
    .out8_shift_i   (out8_shift),
    .out8_sat_i     (out8_sat),
    .rgb_o          (rgb12),
    .rgb8_o, .hsync_o, .vsync_o, .blank_o,   // the core's own outputs, read by the TMDS
    .align_err_o    (align_err),
    .pix_collision_o(pix_collision),
    .cfg_mode_i     (1'b0),
    .cfg_bit_i      (3'b000),
    .cfg_bit_o      (cfg_bit_o),
    .obs_load_i     (1'b0),
    .obs_shift_i    (1'b0),
    .obs_bit_o      (obs_bit_o)
  );

  // The players to the display controller's write ports (one y-processor per colour).
  for (genvar c = 0; c < NumCh; c++) begin : g_col
    assign wr_valid[c][0] = fr_valid[c];
    assign fr_ready[c]    = wr_ready[c][0];
    assign wr_data[c][0]  = fr_data[c];
    assign dc_late[c]     = late[c][0];
  end

  // ------------------------------------------------------------------ TMDS
  de_tmds_enc u_tmds_b (
    .clk_i, .rst_i, .de_i(!blank_o), .data_i(rgb8_o[2]), .c_i({vsync_o, hsync_o}),
    .sym_o(tmds_o[0])
  );
  de_tmds_enc u_tmds_g (
    .clk_i, .rst_i, .de_i(!blank_o), .data_i(rgb8_o[1]), .c_i(2'b00), .sym_o(tmds_o[1])
  );
  de_tmds_enc u_tmds_r (
    .clk_i, .rst_i, .de_i(!blank_o), .data_i(rgb8_o[0]), .c_i(2'b00), .sym_o(tmds_o[2])
  );

  // ------------------------------------------------------------------ status
  logic heart_d, heart_q;
  always_comb heart_d = frame ? ~heart_q : heart_q;
  always_ff @(posedge clk_i) begin
    if (rst_i) heart_q <= 1'b0;
    else       heart_q <= heart_d;
  end

  assign led_o = {pending || malformed != 8'd0 || late_words != 8'd0,
                  |pix_collision, align_err, 2'b00,
                  cmd_count != 16'd0, chk_count != 16'd0 || ferr_count != 16'd0, heart_q};
endmodule

`default_nettype wire
