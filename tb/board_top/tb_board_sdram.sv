// Test top for tb/board_top/test_board_top.py::test_board: the board core
// rtl/board/de_board_core.sv with the timing-checking SDRAM model sim/models/sdram_sdr16.sv
// on its SDRAM pins, as on the board (the I/O buffer joins sd_o.dq / sd_o.dq_oe and the
// model's dq_o / dq_oe_o at the DQ pins, as tb/de_sdram_ctrl/tb_sdram_ctrl.sv does).
// The core's parameters pass through; SdTinitNs shortens the power-up wait of both the
// controller and the model. err_count_o: the model's timing violations.
`default_nettype none

module tb_board_sdram #(
  parameter int unsigned NumChips    = 1,
  parameter int unsigned CarryBug    = 0,
  parameter int unsigned PfDepth     = 2048,
  parameter int unsigned SdTinitNs   = 100_000,
  parameter int unsigned UartClkHz   = 78_125_000,
  parameter int unsigned Baud        = 3_000_000,
  parameter int unsigned TimeoutBits = 22,
  parameter int unsigned BufDepth    = 16,
  parameter int unsigned MaxLines    = 512,
  parameter de_pkg::video_mode_t TestMode = de_pkg::VideoTestDefault,
  parameter int unsigned SpanArray   = 0,
  parameter int unsigned SpanLatency = 300
) (
  input  wire logic            clk_i,
  input  wire logic            clk_core_i,
  input  wire logic            clk_sdram_i,
  input  wire logic            rst_i,
  input  wire logic [1:0]      mode_i,
  input  wire logic            uart_rx_i,
  output      logic            uart_tx_o,
  output      logic [2:0][9:0] tmds_o,
  output      logic [7:0]      led_o,
  output      logic [2:0][7:0] rgb8_o,
  output      logic            hsync_o,
  output      logic            vsync_o,
  output      logic            blank_o,
  // The model's checker.
  output      logic [31:0]     err_count_o,
  output      logic [31:0]     ref_count_o
);
  de_sdram_pkg::sdram_out_t sd;
  logic [15:0] bus;

  de_board_core #(
    .NumChips(NumChips), .CarryBug(CarryBug), .PfDepth(PfDepth), .SdTckPs(8000),
    .SdTinitNs(SdTinitNs), .UartClkHz(UartClkHz), .Baud(Baud), .TimeoutBits(TimeoutBits),
    .BufDepth(BufDepth), .MaxLines(MaxLines), .TestMode(TestMode),
    .SpanArray(SpanArray), .SpanLatency(SpanLatency)
  ) u_core (
    .clk_i, .clk_core_i, .clk_sdram_i, .rst_i, .mode_i, .uart_rx_i, .uart_tx_o, .tmds_o,
    .led_o, .rgb8_o, .hsync_o, .vsync_o, .blank_o,
    .sd_o(sd), .sd_dq_i(bus)
  );

  // The SDRAM chip behind the board's DQ pins.
  sdram_sdr16_pins #(.TckPs(8000), .TinitNs(SdTinitNs)) u_sdram (
    .clk_i(clk_sdram_i), .rst_i, .sd_i(sd), .dq_o(bus), .err_count_o, .ref_count_o
  );
endmodule

`default_nettype wire
