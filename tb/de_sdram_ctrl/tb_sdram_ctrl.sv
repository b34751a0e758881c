// Test top for tb/de_sdram_ctrl: the controller rtl/board/de_sdram_ctrl.sv driving the
// timing-checking model sim/models/sdram_sdr16.sv over the SDRAM pins, as on the board
// (the board's I/O buffer joins sd_o.dq / sd_o.dq_oe / dq_o at the DQ pins). The top
// only wires the two; the bench reads the model's checker on the model (dut.u_sdram).
`default_nettype none

module tb_sdram_ctrl #(
  parameter int unsigned TckPs      = 8000,
  parameter int unsigned CasLatency = 3,
  parameter int unsigned TinitNs    = 2000,
  localparam int unsigned AW        = 23
) (
  input  wire logic          clk_i,
  input  wire logic          rst_i,
  input  wire logic          wr_valid_i,
  output      logic          wr_ready_o,
  input  wire logic [AW-1:0] wr_addr_i,
  input  wire logic [31:0]   wr_data_i,
  input  wire logic          rd_req_valid_i,
  output      logic          rd_req_ready_o,
  input  wire logic [AW-1:0] rd_req_addr_i,
  input  wire logic [1:0]    rd_req_tag_i,
  output      logic          rd_valid_o,
  output      logic [31:0]   rd_data_o,
  output      logic [1:0]    rd_tag_o,
  output      logic          rd_last_o,
  output      logic          init_done_o,
  output      logic          refresh_o
);
  de_sdram_pkg::sdram_out_t sd;
  logic [15:0] bus;

  de_sdram_ctrl #(.TckPs(TckPs), .CasLatency(CasLatency), .TinitNs(TinitNs)) u_ctrl (
    .clk_i, .rst_i,
    .wr_valid_i, .wr_ready_o, .wr_addr_i, .wr_data_i,
    .rd_req_valid_i, .rd_req_ready_o, .rd_req_addr_i, .rd_req_tag_i,
    .rd_valid_o, .rd_data_o, .rd_tag_o, .rd_last_o,
    .init_done_o, .refresh_o,
    .sd_o(sd), .sd_dq_i(bus)
  );

  // The model's counters stay open here: the bench reads them on u_sdram.
  /* verilator lint_off PINCONNECTEMPTY */
  sdram_sdr16_pins #(.TckPs(TckPs), .TinitNs(TinitNs)) u_sdram (
    .clk_i, .rst_i, .sd_i(sd), .dq_o(bus), .err_count_o(), .ref_count_o()
  );
  /* verilator lint_on PINCONNECTEMPTY */
endmodule

`default_nettype wire
