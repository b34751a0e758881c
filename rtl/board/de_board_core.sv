// Board top of the Difference Engine prototype, portable core (docs/board.md).
//
//   uart_rx_i -> de_uart_link -> de_loader -+-> frame store R -> player R -+
//                                          +-> frame store G -> player G -+-> display_controller
//   uart_tx_o <- de_uart_link <-----------+-> frame store B -> player B -+   (3 arrays, NumBuf 1)
//                                                                          |
//   tmds_o[2:0] <- de_tmds_enc x 3 <- rgb8 / hsync / vsync / blank <-------+
//
// The pixel clock (clk_i), plus clk_core_i for the UART (always: 3 Mbaud needs a clock
// with an integer bit period, de_uart_link) and for the span-serial arrays when
// SpanArray = 1 (9 * NumChips columns each in block RAM, docs/fpga.md 3). The board shell (fpga/ulx3s/) adds the PLL, the 10:1 serialisers and the
// pins. Colour: one frame store, one player and one
// instruction buffer per colour (the display controller's one-buffer-per-colour
// choice, docs/display-controller.md §9.1); each player is the single y-processor of
// its colour. TMDS channel 0 is blue and carries {VSYNC, HSYNC} as {C1, C0} while
// blanking, channel 1 green, channel 2 red (DVI 1.0 §3.1).
`default_nettype none

module de_board_core #(
  parameter int unsigned NumChips    = 1,      // chips of 9 PEs per colour array
  parameter int unsigned CarryBug    = 0,
  parameter int unsigned FsDepth     = 1024,   // frame-store words per colour
  parameter int unsigned UartClkHz   = 78_125_000,  // UART on clk_core_i (de_uart_link)
  parameter int unsigned Baud        = 3_000_000,   // FT231X maximum; divider 26, 0.16 %
  parameter int unsigned TimeoutBits = 22,
  parameter int unsigned BufDepth    = 16,
  parameter int unsigned MaxLines    = 512,
  parameter int unsigned TestHActive = 16,
  parameter int unsigned TestHFp     = 2,
  parameter int unsigned TestHSync   = 3,
  parameter int unsigned TestHBp     = 3,
  parameter int unsigned TestVActive = 6,
  parameter int unsigned TestVFp     = 1,
  parameter int unsigned TestVSync   = 2,
  parameter int unsigned TestVBp     = 2,
  parameter int unsigned SpanArray   = 0,      // 1: span-serial arrays on clk_core_i
  parameter int unsigned SpanLatency = 300,    // their Refresh -> column 0, pixel clocks
  localparam int unsigned AW = $clog2(FsDepth)
) (
  input  logic            clk_i,
  input  logic            clk_core_i,
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
  output logic            blank_o
);
  localparam int unsigned NumCh = 3;

  // ------------------------------------------------------------------ UART + loader
  logic        rx_valid, rx_ferr, tx_valid, tx_ready;
  logic [7:0]  rx_data, tx_data;
  logic [2:0]  fs_we, desc_set, pending, pix_collision;
  logic [AW-1:0] fs_addr;
  logic [31:0] fs_wdata;
  logic [15:0] desc_base, desc_len, ferr_count, chk_count, cmd_count;
  logic [2:0]  desc_window, out8_shift;
  logic        desc_comp, out8_sat, align_err;
  logic [13:0] reg_addr;
  logic [31:0] reg_rdata;
  /* verilator lint_off UNUSEDSIGNAL */
  logic [NumCh-1:0] frame;   // G and B play in lockstep with R; R's count is reported
  /* verilator lint_on UNUSEDSIGNAL */

  de_uart_link #(.ClkHz(UartClkHz), .Baud(Baud)) u_uart (
    .clk_i, .rst_i, .clk_uart_i(clk_core_i), .rx_i(uart_rx_i), .tx_o(uart_tx_o),
    .rx_valid_o(rx_valid), .rx_ferr_o(rx_ferr), .rx_data_o(rx_data),
    .tx_valid_i(tx_valid), .tx_ready_o(tx_ready), .tx_data_i(tx_data)
  );

  de_loader #(
    .FsDepth(FsDepth), .NumChips(NumChips), .TimeoutBits(TimeoutBits)
  ) u_loader (
    .clk_i, .rst_i,
    .rx_valid_i     (rx_valid),
    .rx_data_i      (rx_data),
    .rx_ferr_i      (rx_ferr),
    .tx_valid_o     (tx_valid),
    .tx_ready_i     (tx_ready),
    .tx_data_o      (tx_data),
    .fs_we_o        (fs_we),
    .fs_addr_o      (fs_addr),
    .fs_wdata_o     (fs_wdata),
    .desc_set_o     (desc_set),
    .desc_base_o    (desc_base),
    .desc_len_o     (desc_len),
    .desc_window_o  (desc_window),
    .desc_comp_o    (desc_comp),
    .out8_shift_o   (out8_shift),
    .out8_sat_o     (out8_sat),
    .reg_addr_o     (reg_addr),
    .reg_rdata_i    (reg_rdata),
    .frame_i        (frame[0]),
    .pending_i      (pending),
    .align_err_i    (align_err),
    .pix_collision_i(pix_collision),
    .rx_ferr_count_o(ferr_count),
    .chk_err_count_o(chk_count),
    .cmd_err_count_o(cmd_count)
  );

  // ------------------------------------------------------------------ frame stores
  logic [11:0] vactive;
  always_comb begin
    unique case (mode_i)
      2'd0:    vactive = 12'd480;
      2'd1:    vactive = 12'd485;
      2'd2:    vactive = 12'd1024;
      default: vactive = 12'(TestVActive);
    endcase
  end

  logic [NumCh-1:0][0:0]       wr_valid, wr_ready;
  logic [NumCh-1:0][0:0][47:0] wr_data;

  for (genvar c = 0; c < NumCh; c++) begin : g_col
    de_fs_player #(.FsDepth(FsDepth)) u_player (
      .clk_i, .rst_i,
      .fs_we_i      (fs_we[c]),
      .fs_addr_i    (fs_addr),
      .fs_wdata_i   (fs_wdata),
      .desc_set_i   (desc_set[c]),
      .desc_base_i  (desc_base),
      .desc_len_i   (desc_len),
      .desc_window_i(desc_window),
      .desc_comp_i  (desc_comp),
      .vactive_i    (vactive),
      .wr_valid_o   (wr_valid[c][0]),
      .wr_ready_i   (wr_ready[c][0]),
      .wr_data_o    (wr_data[c][0]),
      .frame_o      (frame[c]),
      .pending_o    (pending[c])
    );
  end

  // ------------------------------------------------------------------ display controller
  /* verilator lint_off UNUSEDSIGNAL */
  logic [11:0]            line;
  logic                   window;
  logic [NumCh-1:0][0:0]  done, late;
  logic [NumCh-1:0][11:0] rgb12;
  logic [NumCh-1:0]       cfg_bit_o, obs_bit_o;
  /* verilator lint_on UNUSEDSIGNAL */
  logic [NumCh-1:0][7:0]  rgb8;
  logic                   hsync, vsync, blank;

  display_controller #(
    .NumChips   (NumChips),
    .CarryBug   (CarryBug),
    .NumBuf     (1),
    .BufDepth   (BufDepth),
    .NumBins    (16),
    .BinShift   (7),
    .MaxLines   (MaxLines),
    .TestHActive(TestHActive),
    .TestHFp    (TestHFp),
    .TestHSync  (TestHSync),
    .TestHBp    (TestHBp),
    .TestVActive(TestVActive),
    .TestVFp    (TestVFp),
    .TestVSync  (TestVSync),
    .TestVBp    (TestVBp),
    .SpanArray  (SpanArray),
    .SpanLatency(SpanLatency)
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
    .rgb8_o         (rgb8),
    .hsync_o        (hsync),
    .vsync_o        (vsync),
    .blank_o        (blank),
    .align_err_o    (align_err),
    .pix_collision_o(pix_collision),
    .cfg_mode_i     (1'b0),
    .cfg_bit_i      (3'b000),
    .cfg_bit_o      (cfg_bit_o),
    .obs_load_i     (1'b0),
    .obs_shift_i    (1'b0),
    .obs_bit_o      (obs_bit_o)
  );

  // ------------------------------------------------------------------ TMDS
  de_tmds_enc u_tmds_b (
    .clk_i, .rst_i, .de_i(!blank), .data_i(rgb8[2]), .c_i({vsync, hsync}), .sym_o(tmds_o[0])
  );
  de_tmds_enc u_tmds_g (
    .clk_i, .rst_i, .de_i(!blank), .data_i(rgb8[1]), .c_i(2'b00), .sym_o(tmds_o[1])
  );
  de_tmds_enc u_tmds_r (
    .clk_i, .rst_i, .de_i(!blank), .data_i(rgb8[0]), .c_i(2'b00), .sym_o(tmds_o[2])
  );

  // ------------------------------------------------------------------ status
  logic heart_d, heart_q;
  always_comb heart_d = frame[0] ? ~heart_q : heart_q;
  always_ff @(posedge clk_i) begin
    if (rst_i) heart_q <= 1'b0;
    else       heart_q <= heart_d;
  end

  assign led_o   = {|pending, |pix_collision, align_err, 2'b00,
                    cmd_count != 16'd0, chk_count != 16'd0 || ferr_count != 16'd0, heart_q};
  assign rgb8_o  = rgb8;
  assign hsync_o = hsync;
  assign vsync_o = vsync;
  assign blank_o = blank;
endmodule

`default_nettype wire
