// ULX3S (LFE5U-85F-6 CABGA381) board shell around the portable core rtl/board/
// de_board_core.sv (docs/board.md §7).
//
//   clk_25mhz -> EHXPLLL (VCO 625 MHz) -> CLKOP 125 MHz (TMDS DDR bit clock, 5x; also
//                                         the SDRAM controller's clock, clk_sdram_i)
//                                      -> CLKOS  25 MHz (pixel clock)
//                                      -> CLKOS2 78.125 MHz (span-serial arrays' core
//                                         clock, SpanArray = 1: 625 / 8; the arrays'
//                                         FIFOs make the ratio to the pixel clock free)
//   btn[1] (FIRE1) or PLL not locked -> synchronous reset of the pixel domain
//   ftdi_txd (FPGA receives) / ftdi_rxd (FPGA transmits): the loader's UART
//   gpdi_dp[3:0]: TMDS blue/green/red/clock through ODDRX1F, 2 bits per 125 MHz clock;
//   the pins are LVCMOS33D (fpga/ulx3s/ulx3s.lpf), so each N pin is driven inverted.
//   sdram_*: the 32 MB SDR SDRAM, the frame store (docs/board.md §9): commands and
//   addresses straight from the controller's output registers (clk_shift), DQ through
//   BB buffers (T = not output enable), sdram_clk = clk_shift forwarded inverted by an
//   ODDRX1F (D0 0, D1 1: 180 degrees), so the part samples the commands in the middle of
//   their 8 ns and its read data lands in the controller's capture window (the timing
//   analysis and what it assumes: docs/board.md §9).
//
// Pixel clock 25.0 MHz rather than 25.175 MHz (docs/board.md §5): 25 MHz x 5 = 125 MHz
// comes from the board oscillator with integer dividers; 25.175 MHz would need a
// reference divider above 8 (PFD below the ECP5's 3.125 MHz minimum).
//
// The core's parameters (NumChips, PfDepth; the UART keeps the core defaults UartClkHz
// 78.125 MHz = clk_core, Baud 3,000,000: 26 clocks per bit, docs/board.md §3) are set
// by the Makefile when read_slang elaborates de_board_core; this file is read by yosys'
// own parser (it needs the ECP5 primitives' parameters), so it passes none.
`default_nettype none

module ulx3s_top (
  input  logic       clk_25mhz,
  input  logic [6:0] btn,
  input  logic       ftdi_txd,
  output logic       ftdi_rxd,
  output logic [7:0] led,
  output logic [3:0] gpdi_dp,
  output logic        sdram_clk,
  output logic        sdram_cke,
  output logic        sdram_csn,
  output logic        sdram_rasn,
  output logic        sdram_casn,
  output logic        sdram_wen,
  output logic [1:0]  sdram_ba,
  output logic [12:0] sdram_a,
  output logic [1:0]  sdram_dqm,
  inout  wire  [15:0] sdram_d
);
  // ------------------------------------------------------------------ clocks
  logic clk_shift, clk_pix, clk_core, pll_locked;

  (* FREQUENCY_PIN_CLKI = "25" *)
  (* FREQUENCY_PIN_CLKOP = "125" *)
  (* FREQUENCY_PIN_CLKOS = "25" *)
  (* FREQUENCY_PIN_CLKOS2 = "78.125" *)
  (* ICP_CURRENT = "12" *) (* LPF_RESISTOR = "8" *)
  (* MFG_ENABLE_FILTEROPAMP = "1" *) (* MFG_GMCREF_SEL = "2" *)
  EHXPLLL #(
    .PLLRST_ENA     ("DISABLED"),
    .INTFB_WAKE     ("DISABLED"),
    .STDBY_ENABLE   ("DISABLED"),
    .DPHASE_SOURCE  ("DISABLED"),
    .OUTDIVIDER_MUXA("DIVA"),
    .OUTDIVIDER_MUXB("DIVB"),
    .OUTDIVIDER_MUXC("DIVC"),
    .OUTDIVIDER_MUXD("DIVD"),
    .CLKI_DIV       (1),      // PFD 25 MHz
    .CLKFB_DIV      (5),      // VCO = 25 x 5 x CLKOP_DIV = 625 MHz
    .FEEDBK_PATH    ("CLKOP"),
    .CLKOP_ENABLE   ("ENABLED"),
    .CLKOP_DIV      (5),      // 125 MHz
    .CLKOP_CPHASE   (2),
    .CLKOP_FPHASE   (0),
    .CLKOS_ENABLE   ("ENABLED"),
    .CLKOS_DIV      (25),     // 25 MHz
    .CLKOS_CPHASE   (2),
    .CLKOS_FPHASE   (0),
    .CLKOS2_ENABLE  ("ENABLED"),
    .CLKOS2_DIV     (8),      // 78.125 MHz
    .CLKOS2_CPHASE  (2),
    .CLKOS2_FPHASE  (0)
  ) u_pll (
    .RST         (1'b0),
    .STDBY       (1'b0),
    .CLKI        (clk_25mhz),
    .CLKOP       (clk_shift),
    .CLKOS       (clk_pix),
    .CLKOS2      (clk_core),
    .CLKFB       (clk_shift),
    .CLKINTFB    (),
    .PHASESEL0   (1'b0),
    .PHASESEL1   (1'b0),
    .PHASEDIR    (1'b1),
    .PHASESTEP   (1'b1),
    .PHASELOADREG(1'b1),
    .PLLWAKESYNC (1'b0),
    .ENCLKOP     (1'b0),
    .LOCK        (pll_locked)
  );

  // ------------------------------------------------------------------ reset (pixel domain)
  // The button and the lock are asynchronous: two synchroniser flip-flops, then a
  // 16-clock stretch so every block sees a clean multi-cycle synchronous reset.
  logic [1:0] rst_sync_q;
  logic [4:0] rst_cnt_q;
  logic       rst_pix;
  always_ff @(posedge clk_pix) begin
    rst_sync_q <= {rst_sync_q[0], btn[1] | ~pll_locked};
    if (rst_sync_q[1])        rst_cnt_q <= 5'd0;
    else if (!rst_cnt_q[4])   rst_cnt_q <= rst_cnt_q + 5'd1;
  end
  assign rst_pix = ~rst_cnt_q[4];

  // ------------------------------------------------------------------ core
  logic [2:0][9:0] tmds;
  logic [7:0]      led_core;
  /* verilator lint_off UNUSEDSIGNAL */
  logic [2:0][7:0] rgb8;
  logic            hsync, vsync, blank;
  /* verilator lint_on UNUSEDSIGNAL */

  de_sdram_pkg::sdram_out_t sd;
  logic [15:0] sd_dq_i;

  de_board_core u_core (
    .clk_i    (clk_pix),
    .clk_core_i(clk_core),
    .clk_sdram_i(clk_shift),
    .rst_i    (rst_pix),
    .mode_i   (2'd0),          // 640x480 timing (VESA DMT totals 800 x 525)
    .uart_rx_i(ftdi_txd),
    .uart_tx_o(ftdi_rxd),
    .tmds_o   (tmds),
    .led_o    (led_core),
    .rgb8_o   (rgb8),
    .hsync_o  (hsync),
    .vsync_o  (vsync),
    .blank_o  (blank),
    .sd_o     (sd),
    .sd_dq_i   (sd_dq_i)
  );
  assign led = led_core;

  // ------------------------------------------------------------------ SDRAM pins
  assign sdram_cke  = sd.cke;
  assign sdram_csn  = sd.cs_n;
  assign sdram_rasn = sd.ras_n;
  assign sdram_casn = sd.cas_n;
  assign sdram_wen  = sd.we_n;
  assign sdram_ba   = sd.ba;
  assign sdram_a    = sd.a;
  assign sdram_dqm  = sd.dqm;
  for (genvar i = 0; i < 16; i++) begin : g_dq
    BB u_bb (.I(sd.dq[i]), .T(~sd.dq_oe), .O(sd_dq_i[i]), .B(sdram_d[i]));
  end
  ODDRX1F u_sdram_clk (.SCLK(clk_shift), .RST(1'b0), .D0(1'b0), .D1(1'b1), .Q(sdram_clk));

  // ------------------------------------------------------------------ 10:1 serialisers
  // The pixel domain toggles pix_tog_q every pixel clock, together with the symbols.
  // The shift domain sees the toggle through two flip-flops and loads the symbols in the
  // clock after it sees it change: at least two shift clocks (16 ns) after the symbols
  // changed and at least two before they change again, whatever the phase between the
  // two clocks after lock. Then 5 shift clocks x 2 bits (DDR) send the 10 bits, LSB first.
  logic pix_tog_q;
  always_ff @(posedge clk_pix) pix_tog_q <= ~pix_tog_q;

  logic [2:0] tog_sync_q;
  logic [2:0][9:0] sh_q;
  logic [9:0]      shc_q;
  always_ff @(posedge clk_shift) begin
    tog_sync_q <= {tog_sync_q[1:0], pix_tog_q};
    if (tog_sync_q[2] != tog_sync_q[1]) begin
      sh_q  <= tmds;
      shc_q <= 10'b0000011111;   // the TMDS clock: one pixel period, high first half
    end else begin
      for (int c = 0; c < 3; c++) sh_q[c] <= {2'b00, sh_q[c][9:2]};
      shc_q <= {2'b00, shc_q[9:2]};
    end
  end

  for (genvar c = 0; c < 4; c++) begin : g_ddr
    logic d0, d1;
    if (c < 3) begin : g_data
      assign d0 = sh_q[c][0];
      assign d1 = sh_q[c][1];
    end else begin : g_clk
      assign d0 = shc_q[0];
      assign d1 = shc_q[1];
    end
    ODDRX1F u_oddr (.SCLK(clk_shift), .RST(1'b0), .D0(d0), .D1(d1), .Q(gpdi_dp[c]));
  end
endmodule

`default_nettype wire
