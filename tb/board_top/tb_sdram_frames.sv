// Test top for tb/board_top/test_sdram_frames.py: the SDRAM frame store
// rtl/board/de_sdram_frames.sv alone on the timing-checking SDRAM model
// sim/models/sdram_sdr16.sv (DQ joined at the pins as in tb_board_sdram.sv), with the
// words each player takes from its prefetch FIFO brought out for the checker. The model's
// counters are read on the model (dut.u_sdram); tb_board_sdram brings them out for
// sim/board's C++ harness.
`default_nettype none

module tb_sdram_frames #(
  parameter int unsigned PfDepth   = 16,
  parameter int unsigned SdTinitNs = 2000
) (
  input  wire logic             clk_i,
  input  wire logic             clk_sdram_i,
  input  wire logic             rst_i,
  input  wire logic [11:0]      vactive_i,
  input  wire logic             cmd_valid_i,
  output      logic             cmd_ready_o,
  input  wire logic [56:0]      cmd_i,
  input  wire logic [2:0]       wr_ready_i,
  output      logic [2:0]       wr_valid_o,
  // The players' takes (pixel clock): {comp, window, word} per colour.
  output      logic [2:0]       take_o,
  output      logic [2:0][35:0] take_data_o,
  output      logic [7:0]       malformed_o,
  output      logic [7:0]       late_o,
  output      logic             q_pending_o,
  output      logic             sd_init_done_o
);
  de_sdram_pkg::sdram_out_t sd;
  logic [15:0] bus;
  logic [2:0][47:0] wr_data;
  logic        frame;

  de_sdram_frames #(.PfDepth(PfDepth), .SdTckPs(8000), .SdTinitNs(SdTinitNs)) u_fr (
    .clk_i, .rst_i, .clk_sdram_i, .vactive_i, .cmd_valid_i, .cmd_ready_o, .cmd_i,
    .wr_valid_o, .wr_ready_i, .wr_data_o(wr_data), .dc_late_i(3'b000),
    .frame_o(frame), .q_pending_o, .malformed_o, .late_o, .sd_init_done_o,
    .sd_o(sd), .sd_dq_i(bus)
  );

  assign take_o      = u_fr.pf_take & u_fr.pf_rvalid;
  assign take_data_o = u_fr.pf_rdata;

  // The model's counters stay open here: the bench reads them on u_sdram.
  /* verilator lint_off PINCONNECTEMPTY */
  sdram_sdr16_pins #(.TckPs(8000), .TinitNs(SdTinitNs)) u_sdram (
    .clk_i(clk_sdram_i), .rst_i, .sd_i(sd), .dq_o(bus), .err_count_o(), .ref_count_o()
  );
  /* verilator lint_on PINCONNECTEMPTY */

  logic unused;
  assign unused = ^{wr_data, frame};
endmodule

`default_nettype wire
