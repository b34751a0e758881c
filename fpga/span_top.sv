// FPGA measurement wrapper for the span-serial virtual array: NumColours independent
// de_span_array instances of NumCols columns each (docs/fpga.md, "Span-serial array").
//
// Not part of the design: like chip_top.sv it gives place-and-route a top whose timed
// paths all start and end at flip-flops, with a handful of pins. Each colour takes its
// slot and valid bit from its own slice of one serial-in shift register (so no two
// instances see the same inputs and none can be merged or folded as constant); every
// output bit of every instance goes into a registered XOR fold on one pin.
`default_nettype none

module span_top #(
  parameter int unsigned NumCols    = 648,
  parameter int unsigned MaxSlots   = 4,
  parameter int unsigned NumColours = 3
) (
  input  logic clk_i,
  input  logic rst_i,
  input  logic sin_i,
  output logic fold_o
);
  localparam int unsigned InW  = 1 + 12 + 36;            // valid, identifier, data
  localparam int unsigned OutW = 1 + 1 + 12 + 12 + 1;    // ready, pixel valid/value/col, busy
  localparam int unsigned Grp  = 4;
  localparam int unsigned NGrp = (NumColours * OutW + Grp - 1) / Grp;

  logic rst_q;
  logic [NumColours*InW-1:0] sh_q;
  logic [NGrp*Grp-1:0] out_vec;
  logic [NGrp-1:0] fold1_q;
  logic fold_q;
  logic [OutW-1:0] outs [NumColours];

  always_ff @(posedge clk_i) begin
    rst_q <= rst_i;
    sh_q  <= {sh_q[NumColours*InW-2:0], sin_i};
  end

  always_comb begin
    out_vec = '0;
    for (int c = 0; c < NumColours; c++) begin
      out_vec[c*OutW +: OutW] = outs[c];
    end
  end

  for (genvar c = 0; c < NumColours; c++) begin : g_colour
    logic [InW-1:0] in;
    assign in = sh_q[c*InW +: InW];
    de_span_array #(.NumCols(NumCols), .MaxSlots(MaxSlots)) u_span (
      .clk_i,
      .rst_i         (rst_q),
      .instr_valid_i (in[48]),
      .instr_ready_o (outs[c][26]),
      .id_i          (in[47:36]),
      .data_i        (in[35:0]),
      .pix_valid_o   (outs[c][25]),
      .pix_o         (outs[c][24:13]),
      .pix_col_o     (outs[c][12:1]),
      .busy_o        (outs[c][0])
    );
  end

  always_ff @(posedge clk_i) begin
    for (int g = 0; g < NGrp; g++) begin
      fold1_q[g] <= ^out_vec[g*Grp +: Grp];
    end
    fold_q <= ^fold1_q;
  end
  assign fold_o = fold_q;
endmodule

`default_nettype wire
