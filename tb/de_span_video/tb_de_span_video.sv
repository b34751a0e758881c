// Testbench top: the plain array and the span-serial array behind its pixel-bus
// contract, side by side on one instruction bus (tb/de_span_video). The bench drives the
// bus and reads each array's own outputs (dut.u_array, dut.u_span).
`default_nettype none

module tb_de_span_video #(
  parameter int unsigned NumChips = 2,
  parameter int unsigned Latency  = 60,
  parameter int unsigned CarryBug = 0
) (
  input  logic        clk_i,
  input  logic        clk_core_i,
  input  logic        rst_i,
  input  logic [11:0] id_i,
  input  logic [35:0] data_i
);
  /* verilator lint_off UNUSEDSIGNAL */
  logic [11:0] a_id, a_pix, s_pix;
  logic [35:0] a_data;
  logic [15:0] n_pe;
  logic        a_pix_valid, s_pix_valid, coll, cfg_o, obs_o, late, overflow;
  /* verilator lint_on UNUSEDSIGNAL */

  de_array #(.NumChips(NumChips), .CarryBug(CarryBug)) u_array (
    .clk_i, .rst_i, .id_i, .data_i, .id_o(a_id), .data_o(a_data),
    .pix_valid_o(a_pix_valid), .pix_o(a_pix), .n_pe_o(n_pe), .pix_collision_o(coll),
    .cfg_mode_i(1'b0), .cfg_bit_i(1'b0), .cfg_bit_o(cfg_o),
    .obs_load_i(1'b0), .obs_shift_i(1'b0), .obs_bit_o(obs_o)
  );

  de_span_video #(.NumCols(9 * NumChips), .CarryBug(CarryBug), .Latency(Latency),
                  .NumLineBuf(8)) u_span (
    .clk_i, .rst_i, .clk_core_i, .id_i, .data_i,
    .pix_valid_o(s_pix_valid), .pix_o(s_pix), .late_o(late), .overflow_o(overflow)
  );
endmodule

`default_nettype wire
