// Difference Engine - video timing generator (part of the Access Controller, Kuijk 1995
// §7.5; design and mode table in docs/display-controller.md).
//
// Counts h (pixel slots) and v (lines) in the *issue* time base: the cycle in which
// (h, v) is current is the cycle in which the Access Controller decides what goes on
// the instruction bus for that slot. The Refresh of line v is decided at h = 0. The
// sync/blank outputs here are therefore early; de_access_ctrl delays them to match the
// array.
//
// Line layout (both axes): [0, Active) active, then front porch, sync, back porch.
// mode_i is sampled while rst_i is high and held until the next reset.
`default_nettype none

module de_video_timing #(
  // Mode 3 ("test mode"): small totals for fast simulation and formal checks.
  parameter de_pkg::video_mode_t TestMode = de_pkg::VideoTestDefault
) (
  input  logic        clk_i,
  input  logic        rst_i,
  input  logic [1:0]  mode_i,
  // Counters (issue time base).
  output logic [11:0] h_o,
  output logic [11:0] v_o,
  output logic [11:0] h_total_o,
  output logic [11:0] v_total_o,
  output logic [11:0] v_active_o,
  // Undelayed video signals, active high; *pol_o = 1 if the mode's pulse is positive.
  output logic        hsync_o,
  output logic        vsync_o,
  output logic        de_o,
  output logic        hpol_o,
  output logic        vpol_o,
  // Slot qualifiers.
  output logic        line_start_o,       // h == 0: the Refresh slot
  output logic        next_active_o,      // line v+1 (mod total) is an active line
  output logic [11:0] next_line_o         // v+1 (mod total)
);

  localparam int unsigned TestHTotal = int'(TestMode.h_act) + int'(TestMode.h_fp)
                                     + int'(TestMode.h_sync) + int'(TestMode.h_bp);
  localparam int unsigned TestVTotal = int'(TestMode.v_act) + int'(TestMode.v_fp)
                                     + int'(TestMode.v_sync) + int'(TestMode.v_bp);

  // Parameter checks at elaboration.
  if (TestMode.h_act < 1 || TestMode.h_sync < 1 || TestMode.v_act < 1 || TestMode.v_sync < 1)
  begin : g_bad_test_zero
    $fatal(1, "de_video_timing: test mode needs non-zero active and sync widths");
  end
  if (TestHTotal < 4 || TestHTotal > 4095 || TestVTotal < 2 || TestVTotal > 4095)
  begin : g_bad_test_total
    $fatal(1, "de_video_timing: test mode totals must be in 4..4095 / 2..4095");
  end

  // Mode table: spec/video.toml through de_pkg::video_mode (docs/display-controller.md
  // §3); the test mode's geometry comes from the TestMode parameter. Package names are
  // written qualified: tb/formal reads this file with yosys's own parser, which has no
  // `import`.
  logic [11:0] h_act, h_fp, h_sync, h_bp, v_act, v_fp, v_sync, v_bp;
  logic        h_pol, v_pol;  // 1 = active-high sync pulse
  logic [1:0]  mode_d, mode_q;
  de_pkg::video_mode_t vm;
  // Only its v_act is used: the reset value of v_q.
  /* verilator lint_off UNUSEDSIGNAL */
  de_pkg::video_mode_t vm_rst;
  /* verilator lint_on UNUSEDSIGNAL */

  function automatic de_pkg::video_mode_t mode_of(logic [1:0] m);
    if (m == de_pkg::VideoModeTest) begin
      mode_of = TestMode;
    end else begin
      mode_of = de_pkg::video_mode(m);
    end
  endfunction

  assign vm = mode_of(mode_q);
  assign {h_act, h_fp, h_sync, h_bp} = {vm.h_act, vm.h_fp, vm.h_sync, vm.h_bp};
  assign {v_act, v_fp, v_sync, v_bp} = {vm.v_act, vm.v_fp, vm.v_sync, vm.v_bp};
  assign {h_pol, v_pol} = {vm.h_pol, vm.v_pol};
  // The mode being loaded, for the reset value of v_q (mode_q is not yet loaded then).
  assign vm_rst = mode_of(mode_i);

  logic [11:0] h_total, v_total;
  logic [11:0] h_d, h_q, v_d, v_q;

  assign h_total = h_act + h_fp + h_sync + h_bp;
  assign v_total = v_act + v_fp + v_sync + v_bp;

  always_comb begin
    mode_d = mode_q;
    h_d    = h_q;
    v_d    = v_q;
    if (h_q == h_total - 12'd1) begin
      h_d = '0;
      v_d = (v_q == v_total - 12'd1) ? 12'd0 : v_q + 12'd1;
    end else begin
      h_d = h_q + 12'd1;
    end
  end

  always_ff @(posedge clk_i) begin
    if (rst_i) begin
      mode_q <= mode_i;
      h_q    <= '0;
      // Start at the first vertical-blank line: the y-processors get a whole vertical
      // blank to fill their buffers before the window of line 0 opens.
      v_q    <= vm_rst.v_act;
    end else begin
      mode_q <= mode_d;
      h_q    <= h_d;
      v_q    <= v_d;
    end
  end

  logic h_in_sync, v_in_sync;
  assign h_in_sync = (h_q >= h_act + h_fp) && (h_q < h_act + h_fp + h_sync);
  assign v_in_sync = (v_q >= v_act + v_fp) && (v_q < v_act + v_fp + v_sync);

  assign h_o          = h_q;
  assign v_o          = v_q;
  assign h_total_o    = h_total;
  assign v_total_o    = v_total;
  assign v_active_o   = v_act;
  assign hsync_o      = h_in_sync;
  assign vsync_o      = v_in_sync;
  assign hpol_o       = h_pol;
  assign vpol_o       = v_pol;
  assign de_o         = (h_q < h_act) && (v_q < v_act);
  assign line_start_o = (h_q == 12'd0);
  assign next_line_o  = (v_q == v_total - 12'd1) ? 12'd0 : v_q + 12'd1;
  assign next_active_o = (next_line_o < v_act);

endmodule

`default_nettype wire
