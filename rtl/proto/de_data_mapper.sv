// Data mapper of the prototype's input circuit (Kuijk 1995, 7.6.2 and 7.7).
// Expands a 32-bit frame-store word (5-bit LUT code + 27-bit operand) into the 48-bit
// instruction (12-bit identifier + 36-bit 12.24 data) for a 6-bit DAC window at pixel
// bits [w+5:w], w = 0..4, and optionally applies the carry-bug compensation.
// One registered stage; the reference model is diffengine.binfmt.map_word.
`default_nettype none

module de_data_mapper
  import de_pkg::*;
(
  input  logic        clk_i,
  input  logic        rst_i,
  input  logic        valid_i,
  input  logic [31:0] word_i,
  input  logic [2:0]  window_i,      // w: the DAC window's lowest pixel bit, 0..4
  input  logic        compensate_i,  // apply the 7.7 carry-bug compensation
  output logic        valid_o,
  output logic [IdW-1:0]   id_o,
  output logic [DataW-1:0] data_o
);
  logic [11:0] ident;
  logic [1:0]  op_type;
  logic [26:0] operand;
  logic [35:0] data_d, data_q;
  logic [11:0] ident_d, ident_q;
  logic        valid_d, valid_q;
  logic [2:0]  w;

  de_instr_lut u_lut (
    .code_i(word_i[31:27]),
    .id_o  (ident),
    .type_o(op_type)
  );

  assign operand = word_i[26:0];
  // Windows above 4 leave no room for the sign bit in 36 bits; clamp rather than wrap.
  assign w = (window_i > 3'd4) ? 3'd4 : window_i;

  logic [35:0] int_wide;
  logic [11:0] i12;
  logic [35:0] comp;

  always_comb begin
    // Intensity: sign-extend the 27-bit operand to 36 bits, then shift it so that its
    // 6 window bits land on pixel bits [w+5:w], i.e. D bits [29+w:24+w].
    int_wide = {{9{operand[26]}}, operand} << (4'd4 + {1'b0, w});
    // Eval0 intensity: 7 bits (sign + 6 window bits) placed at pixel bits [w+6:w].
    i12 = {{5{operand[26]}}, operand[26:20]} << w;
    // 7.7: halve the 24-bit fraction so a fraction overflow (+2 under the fault) means 1.0.
    comp = {int_wide[DataW-1:FracW], 1'b0, int_wide[FracW-1:1]};

    // An idle cycle enters the array as a Nop.
    ident_d = valid_i ? ident : IdNop;
    valid_d = valid_i;
    data_d  = 36'd0;
    if (valid_i) begin
      unique case (op_type)
        TypeAddress:   data_d = {i12, 2'b00, operand[19:10], 2'b00, operand[9:0]};
        TypeIntensity: data_d = compensate_i ? comp : int_wide;
        default:       data_d = '0;
      endcase
    end
  end

  always_ff @(posedge clk_i) begin
    if (rst_i) begin
      valid_q <= 1'b0;
      ident_q <= 12'h000;
      data_q  <= 36'd0;
    end else begin
      valid_q <= valid_d;
      ident_q <= ident_d;
      data_q  <= data_d;
    end
  end

  assign valid_o = valid_q;
  assign id_o    = ident_q;
  assign data_o  = data_q;
endmodule

`default_nettype wire
