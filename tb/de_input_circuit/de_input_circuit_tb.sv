// Test wrapper: the prototype's input circuit (LUT + data mapper -> skew) followed by
// the output deskew, so one bench checks the expansion and that skew/deskew cancel.
module de_input_circuit_tb (
  input  logic        clk_i,
  input  logic        rst_i,
  input  logic        valid_i,
  input  logic [31:0] word_i,
  input  logic [2:0]  window_i,
  input  logic        compensate_i,
  output logic        valid_o,
  output logic [11:0] id_o,
  output logic [35:0] data_o,
  output logic [11:0] skew_ident_o,
  output logic [35:0] skew_blk_o,      // {block 2, block 1, block 0}, skewed
  output logic [11:0] deskew_ident_o,
  output logic [35:0] deskew_data_o
);
  de_data_mapper u_mapper (
    .clk_i, .rst_i, .valid_i, .word_i, .window_i, .compensate_i,
    .valid_o, .id_o, .data_o
  );
  de_skew u_skew (
    .clk_i, .rst_i, .id_i(id_o), .data_i(data_o), .id_o(skew_ident_o), .blk_o(skew_blk_o)
  );
  de_deskew u_deskew (
    .clk_i, .rst_i, .id_i(skew_ident_o), .blk_i(skew_blk_o),
    .id_o  (deskew_ident_o), .data_o(deskew_data_o)
  );
endmodule
