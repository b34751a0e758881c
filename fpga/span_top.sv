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
  // In: valid, then one record {identifier, data} (de_pkg RecW), split as de_pkg's
  // rec_id / rec_data split it; as slices, since calling them gave yosys an equivalent
  // but differently mapped netlist (issue 17: the change had to keep it equal).
  localparam int unsigned InW  = 1 + de_pkg::RecW;
  // Out: ready, pixel valid, pixel, its column (de_span_array's pix_col_o), busy.
  localparam int unsigned ColW = 12;
  localparam int unsigned OutW = 1 + 1 + de_pkg::PixW + ColW + 1;
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
      .instr_valid_i (in[InW-1]),
      .instr_ready_o (outs[c][OutW-1]),
      .id_i          (in[de_pkg::RecW-1 -: de_pkg::IdW]),
      .data_i        (in[de_pkg::DataW-1:0]),
      .pix_valid_o   (outs[c][OutW-2]),
      .pix_o         (outs[c][1+ColW +: de_pkg::PixW]),
      .pix_col_o     (outs[c][1 +: ColW]),
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
