// Test wrapper: the prototype's input circuit (LUT + data mapper -> skew) followed by
// the output deskew, so one bench checks the expansion and that skew/deskew cancel. The
// bench drives the mapper's inputs and reads each block's own outputs (dut.u_mapper,
// dut.u_skew, dut.u_deskew).
`default_nettype none

module de_input_circuit_tb (
  input  logic        clk_i,
  input  logic        rst_i,
  input  logic        valid_i,
  input  logic [31:0] word_i,
  input  logic [2:0]  window_i,
  input  logic        compensate_i
);
  /* verilator lint_off UNUSEDSIGNAL */
  logic        valid;
  logic [11:0] id, skew_id, deskew_id;
  logic [35:0] data, skew_blk, deskew_data;
  /* verilator lint_on UNUSEDSIGNAL */

  de_data_mapper u_mapper (
    .clk_i, .rst_i, .valid_i, .word_i, .window_i, .compensate_i,
    .valid_o(valid), .id_o(id), .data_o(data)
  );
  de_skew u_skew (
    .clk_i, .rst_i, .id_i(id), .data_i(data), .id_o(skew_id), .blk_o(skew_blk)
  );
  de_deskew u_deskew (
    .clk_i, .rst_i, .id_i(skew_id), .blk_i(skew_blk), .id_o(deskew_id), .data_o(deskew_data)
  );
endmodule

`default_nettype wire
