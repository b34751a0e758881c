// Test top for tb/de_varray: the virtual array and the plain array side by side on the
// same instruction stream. clk_i is the virtual array's core clock; the testbench
// pulses clk_a_i (the plain array's clock) once per step, on the core edge that
// samples the step's slot, so both arrays see the same slots in the same order.
module tb_de_varray
  import de_pkg::*;
#(
  parameter int unsigned NumChips = 2,
  parameter int unsigned CarryBug = 0,
  parameter int unsigned Fold     = 3
) (
  input  logic             clk_i,
  input  logic             clk_a_i,
  input  logic             rst_i,
  input  logic [IdW-1:0]   ident_i,
  input  logic [DataW-1:0] data_i,
  output logic             step_o,
  output logic [IdW-1:0]   v_ident_o,
  output logic [DataW-1:0] v_data_o,
  output logic             v_pixel_valid_o,
  output logic [PixW-1:0]  v_pixel_o,
  output logic             v_collision_o,
  output logic [15:0]      n_pe_o,
  output logic [IdW-1:0]   a_ident_o,
  output logic [DataW-1:0] a_data_o,
  output logic             a_pixel_valid_o,
  output logic [PixW-1:0]  a_pixel_o,
  output logic             a_collision_o
);
  /* verilator lint_off PINCONNECTEMPTY */
  de_varray #(.NumChips(NumChips), .CarryBug(CarryBug), .Fold(Fold)) u_varray (
    .clk_i, .rst_i, .ident_i, .data_i,
    .ident_o(v_ident_o), .data_o(v_data_o),
    .pixel_valid_o(v_pixel_valid_o), .pixel_o(v_pixel_o),
    .n_pe_o, .pix_collision_o(v_collision_o),
    .cfg_mode_i(1'b0), .cfg_bit_i(1'b0), .cfg_bit_o(),
    .obs_load_i(1'b0), .obs_shift_i(1'b0), .obs_bit_o(),
    .step_o
  );
  de_array #(.NumChips(NumChips), .CarryBug(CarryBug)) u_array (
    .clk_i(clk_a_i), .rst_i, .id_i(ident_i), .data_i,
    .id_o (a_ident_o), .data_o(a_data_o),
    .pix_valid_o(a_pixel_valid_o), .pix_o(a_pixel_o),
    .n_pe_o(), .pix_collision_o(a_collision_o),
    .cfg_mode_i(1'b0), .cfg_bit_i(1'b0), .cfg_bit_o(),
    .obs_load_i(1'b0), .obs_shift_i(1'b0), .obs_bit_o()
  );
  /* verilator lint_on PINCONNECTEMPTY */
endmodule
