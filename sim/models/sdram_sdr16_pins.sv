// The SDRAM model on the controller's pin struct, as on the board: sdram_sdr16 (the chip,
// with its vendor-like pin list) behind the DQ pins that the controller (sd_i.dq /
// sd_i.dq_oe) and the chip share. dq_o is what the controller's sd_dq_i sees. Used by every
// testbench that puts de_sdram_ctrl on the model (tb/de_sdram_ctrl, tb/board_top, sim/board).
// Its ports carry the model's two counters (timing violations, refreshes); the rest of
// the checker (the error code, the cycle count) a bench reads on the model itself.
`default_nettype none

module sdram_sdr16_pins #(
  parameter int unsigned TckPs   = 8000,
  parameter int unsigned TinitNs = 100_000
) (
  input  wire logic                     clk_i,
  input  wire logic                     rst_i,
  input  wire de_sdram_pkg::sdram_out_t sd_i,
  output      logic [15:0]              dq_o,
  // The model's checker (sdram_sdr16): timing violations and refreshes seen.
  output      logic [31:0]              err_count_o,
  output      logic [31:0]              ref_count_o
);
  logic        m_oe;
  logic [15:0] m_dq;

  // The DQ pins: whoever drives; both at once is the model's DQ violation (and X here).
  assign dq_o = sd_i.dq_oe ? sd_i.dq : (m_oe ? m_dq : 16'hzzzz);

  logic [15:0] err_seen;
  logic [3:0]  err_code;
  logic [31:0] cycle;
  logic        init_done_m;
  logic [2:0]  cl_m;
  logic [9:0]  bl_m;

  sdram_sdr16 #(.TckPs(TckPs), .TinitNs(TinitNs)) u_sdram (
    .clk_i, .rst_i,
    .cke_i(sd_i.cke), .cs_n_i(sd_i.cs_n), .ras_n_i(sd_i.ras_n), .cas_n_i(sd_i.cas_n),
    .we_n_i(sd_i.we_n), .ba_i(sd_i.ba), .a_i(sd_i.a), .dqm_i(sd_i.dqm), .dq_i(sd_i.dq),
    .dq_o(m_dq), .dq_oe_o(m_oe),
    .err_count_o, .err_seen_o(err_seen), .err_code_o(err_code),
    .cycle_o(cycle),
    .init_done_o(init_done_m), .ref_count_o, .cl_o(cl_m), .bl_o(bl_m)
  );

  logic unused;
  assign unused = ^{err_seen, err_code, cycle, init_done_m, cl_m, bl_m};
endmodule

`default_nettype wire
