// Difference Engine - full-colour display controller (Kuijk 1995 §7.5, Fig. 7.8 and
// the full-colour system of his Appendix C, reconstructed in docs/display-controller.md
// §9).
//
//   y-proc i --wr[R][i]--> buffer R,i --+                          +--> de_array R --+
//            --wr[G][i]--> buffer G,i --+-- de_display_core ------+--> de_array G --+--> RGB
//            --wr[B][i]--> buffer B,i --+  (3 access controllers, +--> de_array B --+
//                                          one timing, 3 monitors)
//
// Each colour has its own array and its own instruction bus (one instruction per clock
// per colour); a y-processor writes one buffer per colour. The pixels of column q of a
// line leave each array NumChips + 3 cycles after its Refresh is on the bus
// (docs/array.md), which sets the sync/blank delay; the core adds one output register to
// pixels and sync alike.
//
// SpanArray = 1 puts the span-serial array (rtl/varray/de_span_video.sv: 9 * NumChips
// columns in block RAM, running on clk_core_i, docs/fpga.md 3) in place of each de_array,
// with SpanLatency pixel clocks from Refresh to column 0. Its late/overflow flags come
// out on pix_collision_o; it has no bypass or observation chain (cfg_bit_o = cfg_bit_i,
// obs_bit_o = 0). With SpanArray = 0, clk_core_i is not used.
`default_nettype none

module display_controller #(
  parameter int unsigned NumChips    = 72,   // 648 PEs per colour (640 columns + spares)
  parameter int unsigned CarryBug    = 0,    // §7.7 fault in every PE (all three arrays)
  parameter int unsigned NumBuf      = 4,    // y-processors
  parameter int unsigned BufDepth    = 16,
  parameter int unsigned SkipW       = 8,
  parameter int unsigned NumBins     = 16,
  parameter int unsigned BinShift    = 7,
  parameter int unsigned MaxLines    = 1024,
  // The test mode's geometry (mode_i = de_pkg::VideoModeTest), spec/video.toml's [test].
  parameter de_pkg::video_mode_t TestMode = de_pkg::VideoTestDefault,
  parameter int unsigned SpanArray   = 0,
  parameter int unsigned SpanLatency = 300,
  // log2 of the span array's pixel -> core FIFO (slots); 8 keeps the tested default, the
  // board takes 11 because the CAD scene's paced backlog reaches 698 slots (docs/board-frames.md)
  parameter int unsigned SpanFifoAw  = 8,
  // de_array InReg (SpanArray = 0): 1 = the arrays of the chip the FPGA flow builds, each
  // PE with its input registered; the same pixels, later (ArrayLatency).
  parameter int unsigned InReg       = 0,
  // docs/array.md: a Refresh on id_i in the cycle ending with edge E puts column q on
  // pix_o right after edge E + NumChips + 2 + q, i.e. NumChips + 3 cycles later; with
  // InReg, (NumPe + 1) NumChips + 4 cycles later (NumPe = 9).
  localparam int unsigned ArrayLatency = SpanArray != 0 ? SpanLatency
                                       : (InReg != 0 ? 10 * NumChips + 4 : NumChips + 3),
  localparam int unsigned NumCh        = 3
) (
  input  logic                                 clk_i,
  input  logic                                 rst_i,
  // The span-serial arrays' core clock (SpanArray = 1 only).
  /* verilator lint_off UNUSEDSIGNAL */
  input  logic                                 clk_core_i,
  /* verilator lint_on UNUSEDSIGNAL */
  input  logic [1:0]                           mode_i,
  // y-processor write ports: [channel 0 = R, 1 = G, 2 = B][y-processor].
  input  logic [NumCh-1:0][NumBuf-1:0]         wr_valid_i,
  output logic [NumCh-1:0][NumBuf-1:0]         wr_ready_o,
  input  logic [NumCh-1:0][NumBuf-1:0][de_pkg::RecW-1:0]   wr_data_i,
  output logic [11:0]                          line_o,
  output logic                                 window_o,
  output logic [NumCh-1:0][NumBuf-1:0]         done_o,
  output logic [NumCh-1:0][NumBuf-1:0]         late_o,
  // Load Monitor read-out ([13:12] channel, 3 = controller registers).
  input  logic [13:0]                          reg_addr_i,
  output logic [31:0]                          reg_rdata_o,
  // Video.
  input  logic [2:0]                           out8_shift_i,
  input  logic                                 out8_sat_i,
  output logic [NumCh-1:0][11:0]               rgb_o,
  output logic [NumCh-1:0][7:0]                rgb8_o,
  output logic                                 hsync_o,
  output logic                                 vsync_o,
  output logic                                 blank_o,
  output logic                                 align_err_o,
  output logic [NumCh-1:0]                     pix_collision_o,
  // Array configuration (bypass) and observation chains, one per colour.
  input  logic                                 cfg_mode_i,
  input  logic [NumCh-1:0]                     cfg_bit_i,
  output logic [NumCh-1:0]                     cfg_bit_o,
  input  logic                                 obs_load_i,
  input  logic                                 obs_shift_i,
  output logic [NumCh-1:0]                     obs_bit_o
);

  if (NumChips < 1 || NumChips * 9 > 4095) begin : g_bad_chips
    // HTotal >= PEs keeps Refreshes n_pe apart; the 12-bit counters cap it at 4095.
    $fatal(1, "display_controller: NumChips must be 1..455");
  end

  logic [NumCh-1:0][de_pkg::RecW-1:0] instr;
  logic [NumCh-1:0][11:0] pix;
  logic [NumCh-1:0]       pix_valid;

  de_display_core #(
    .NumBuf      (NumBuf),
    .BufDepth    (BufDepth),
    .ArrayLatency(ArrayLatency),
    .SkipW       (SkipW),
    .NumBins     (NumBins),
    .BinShift    (BinShift),
    .MaxLines    (MaxLines),
    .TestMode    (TestMode)
  ) u_core (
    .clk_i,
    .rst_i,
    .mode_i,
    .wr_valid_i,
    .wr_ready_o,
    .wr_data_i,
    .line_o,
    .window_o,
    .done_o,
    .late_o,
    .reg_addr_i,
    .reg_rdata_o,
    .instr_o     (instr),
    .pix_i       (pix),
    .pix_valid_i (pix_valid),
    .out8_shift_i,
    .out8_sat_i,
    .rgb_o,
    .rgb8_o,
    .hsync_o,
    .vsync_o,
    .blank_o,
    .align_err_o
  );

  if (SpanArray > 1) begin : g_bad_span
    $fatal(1, "display_controller: SpanArray must be 0 or 1");
  end

  for (genvar c = 0; c < NumCh; c++) begin : g_arr
   if (SpanArray != 0) begin : g_span
    logic late, overflow;
    de_span_video #(
      .NumCols (9 * NumChips),
      .CarryBug(CarryBug),
      .Latency (SpanLatency),
      .FifoAw  (SpanFifoAw)
    ) u_array (
      .clk_i,
      .rst_i,
      .clk_core_i,
      .id_i       (de_pkg::rec_id(instr[c])),
      .data_i     (de_pkg::rec_data(instr[c])),
      .pix_valid_o(pix_valid[c]),
      .pix_o      (pix[c]),
      .late_o     (late),
      .overflow_o (overflow)
    );
    assign pix_collision_o[c] = late || overflow;
    assign cfg_bit_o[c]       = cfg_bit_i[c];
    assign obs_bit_o[c]       = 1'b0;
   end else begin : g_plain
    // The array's pass-through bus (for chaining virtual arrays) and its PE count are
    // not needed here.
    /* verilator lint_off UNUSEDSIGNAL */
    logic [de_pkg::IdW-1:0]   ident_out;
    logic [de_pkg::DataW-1:0] data_out;
    logic [15:0] n_pe;
    /* verilator lint_on UNUSEDSIGNAL */

    de_array #(
      .NumChips(NumChips),
      .CarryBug(CarryBug),
      .InReg   (InReg)
    ) u_array (
      .clk_i,
      .rst_i,
      .id_i           (de_pkg::rec_id(instr[c])),
      .data_i         (de_pkg::rec_data(instr[c])),
      .id_o           (ident_out),
      .data_o         (data_out),
      .pix_valid_o    (pix_valid[c]),
      .pix_o          (pix[c]),
      .n_pe_o         (n_pe),
      .pix_collision_o(pix_collision_o[c]),
      .cfg_mode_i,
      .cfg_bit_i      (cfg_bit_i[c]),
      .cfg_bit_o      (cfg_bit_o[c]),
      .obs_load_i,
      .obs_shift_i,
      .obs_bit_o      (obs_bit_o[c])
    );
   end
  end

endmodule

`default_nettype wire
