// Difference Engine - full-colour display controller without the x-processor arrays
// (Kuijk 1995 §7.5, Fig. 7.8 in colour; design in docs/display-controller.md §9).
//
// * Three colour channels (0 = R, 1 = G, 2 = B), each with its own instruction bus: a
//   de_access_ctrl and NumBuf de_instr_buffers per channel. A y-processor owns buffer i
//   of every channel, i.e. it writes one buffer per colour.
// * The three access controllers are reset together and run in the same mode, so their
//   video timing counters are identical every cycle: all three Refreshes go out in the
//   same slot and channel 0's delayed sync/blank serves all three pixel streams.
// * One Load Monitor per channel behind one host read port (reg_addr_i[13:12] = channel;
//   channel 3 holds the controller's own registers).
// * Output stage: one register for the 12-bit pixels (forced to zero while blanking), the
//   8-bit window (pixel bits [w+7:w], optionally saturated) and hsync/vsync/blank, so
//   everything leaves together.
`default_nettype none

module de_display_core #(
  parameter int unsigned NumBuf       = 4,    // y-processors (buffers per colour)
  parameter int unsigned BufDepth     = 16,   // words per instruction buffer
  parameter int unsigned MaxCmdLen    = 10,
  parameter int unsigned ArrayLatency = 75,   // Refresh on instr_o -> column 0 on pix_i
  parameter int unsigned SkipW        = 8,
  parameter int unsigned NumBins      = 16,
  parameter int unsigned BinShift     = 7,
  parameter int unsigned MaxLines     = 1024,
  // Mode 3's geometry (de_video_timing).
  parameter de_pkg::video_mode_t TestMode = de_pkg::VideoTestDefault,
  localparam int unsigned NumCh       = 3
) (
  input  logic                                 clk_i,
  input  logic                                 rst_i,
  input  logic [1:0]                           mode_i,       // sampled during reset
  // y-processor write ports: [channel][y-processor].
  input  logic [NumCh-1:0][NumBuf-1:0]         wr_valid_i,
  output logic [NumCh-1:0][NumBuf-1:0]         wr_ready_o,
  input  logic [NumCh-1:0][NumBuf-1:0][de_pkg::RecW-1:0]   wr_data_i,
  // Synchronisation for the y-processors (issue time base).
  output logic [11:0]                          line_o,
  output logic                                 window_o,
  output logic [NumCh-1:0][NumBuf-1:0]         done_o,
  output logic [NumCh-1:0][NumBuf-1:0]         late_o,
  // Host register read port (data one clock after the address).
  input  logic [13:0]                          reg_addr_i,
  output logic [31:0]                          reg_rdata_o,
  // Instruction buses to the three arrays and their pixel outputs.
  output logic [NumCh-1:0][de_pkg::RecW-1:0]               instr_o,
  input  logic [NumCh-1:0][11:0]               pix_i,
  input  logic [NumCh-1:0]                     pix_valid_i,
  // Video out: 12 bits per colour and an 8-bit window, sync and blank aligned.
  input  logic [2:0]                           out8_shift_i, // w: window = bits [w+7:w]
  input  logic                                 out8_sat_i,   // clamp <0 -> 0, >255 -> 255
  output logic [NumCh-1:0][11:0]               rgb_o,
  output logic [NumCh-1:0][7:0]                rgb8_o,
  output logic                                 hsync_o,
  output logic                                 vsync_o,
  output logic                                 blank_o,
  output logic                                 align_err_o   // sticky: blank low, no pixel
);

  // Parameter checks at elaboration. NumBuf (1..8) is checked where it is used, by
  // de_access_ctrl and de_load_monitor, which take it unchanged; the core adds the one
  // bound of its own, ArrayLatency >= 1.
  if (ArrayLatency < 1 || ArrayLatency > 4095) begin : g_bad_latency
    $fatal(1, "de_display_core: ArrayLatency must be 1..4095");
  end

  // ---------------------------------------------------------------------------------
  // Channels: buffers + access controller + load monitor.
  logic [NumCh-1:0]             ch_hsync, ch_vsync, ch_de, ch_window;
  logic [NumCh-1:0][11:0]       ch_line;
  logic [NumCh-1:0][NumBuf-1:0] ch_grant;
  logic [NumCh-1:0][31:0]       mon_rdata;

  for (genvar c = 0; c < NumCh; c++) begin : g_ch
    logic [NumBuf-1:0]       rd_valid, rd_ready, drain;
    logic [NumBuf-1:0][de_pkg::RecW-1:0] rd_data;
    logic                    ev_refresh, ev_active, ev_last, ev_issue, ev_free;
    logic [11:0]             ev_line;
    logic [NumBuf-1:0]       ev_late, drop;

    for (genvar i = 0; i < NumBuf; i++) begin : g_buf
      // Status outputs are for waves and testbenches only.
      /* verilator lint_off UNUSEDSIGNAL */
      logic                     full, empty;
      logic [$clog2(BufDepth):0] level, committed;
      /* verilator lint_on UNUSEDSIGNAL */

      de_instr_buffer #(
        .Depth    (BufDepth),
        .MaxCmdLen(MaxCmdLen)
      ) u_buf (
        .clk_i,
        .rst_i,
        .wr_valid_i (wr_valid_i[c][i]),
        .wr_ready_o (wr_ready_o[c][i]),
        .wr_data_i  (wr_data_i[c][i]),
        .rd_valid_o (rd_valid[i]),
        .rd_ready_i (rd_ready[i]),
        .drain_i    (drain[i]),
        .rd_data_o  (rd_data[i]),
        .full_o     (full),
        .empty_o    (empty),
        .level_o    (level),
        .committed_o(committed)
      );
    end

    de_access_ctrl #(
      .NumBuf      (NumBuf),
      .ArrayLatency(ArrayLatency),
      .SkipW       (SkipW),
      .TestMode    (TestMode)
    ) u_ac (
      .clk_i,
      .rst_i,
      .mode_i,
      .buf_valid_i     (rd_valid),
      .buf_data_i      (rd_data),
      .buf_ready_o     (rd_ready),
      .buf_drain_o     (drain),
      .instr_o         (instr_o[c]),
      .grant_o         (ch_grant[c]),
      .hsync_o         (ch_hsync[c]),
      .vsync_o         (ch_vsync[c]),
      .de_o            (ch_de[c]),
      .line_o          (ch_line[c]),
      .window_o        (ch_window[c]),
      .done_o          (done_o[c]),
      .late_o          (late_o[c]),
      .ev_refresh_o    (ev_refresh),
      .ev_line_active_o(ev_active),
      .ev_line_o       (ev_line),
      .ev_last_line_o  (ev_last),
      .ev_late_o       (ev_late),
      .ev_issue_o      (ev_issue),
      .ev_free_o       (ev_free),
      .drop_o          (drop)
    );

    de_load_monitor #(
      .NumBuf  (NumBuf),
      .NumBins (NumBins),
      .BinShift(BinShift),
      .MaxLines(MaxLines)
    ) u_mon (
      .clk_i,
      .rst_i,
      .ev_refresh_i    (ev_refresh),
      .ev_line_active_i(ev_active),
      .ev_line_i       (ev_line),
      .ev_last_line_i  (ev_last),
      .ev_late_i       (ev_late),
      .ev_issue_i      (ev_issue),
      .ev_free_i       (ev_free),
      .drop_i          (drop),
      .reg_addr_i      (reg_addr_i[de_pkg::RegChanLsb-1:0]),
      .reg_rdata_o     (mon_rdata[c])
    );
  end

  // Channels 1 and 2 run the same timing as channel 0 (same reset, same mode), so their
  // copies of the sync/blank/line outputs are redundant; grants are for testbenches.
  logic unused_ch;
  assign unused_ch = ^{ch_hsync[2:1], ch_vsync[2:1], ch_de[2:1], ch_window[2:1],
                       ch_line[2:1], ch_grant};

  assign line_o   = ch_line[0];
  assign window_o = ch_window[0];

  // ---------------------------------------------------------------------------------
  // Host read port: [13:12] selects the channel's monitor; channel 3 = controller info.
  logic [1:0]  reg_ch_d, reg_ch_q;
  logic [31:0] info_d, info_q;
  logic        align_err_d, align_err_q;

  always_comb begin
    reg_ch_d = reg_addr_i[de_pkg::RegChanLsb +: 2];
    info_d   = 32'h0;
    unique case (reg_addr_i[de_pkg::RegChanLsb-1:0])
      // ID: [31:24] 0xDC, [23:20] channels, [19:16] NumBuf, [15:0] ArrayLatency.
      de_pkg::CtrlRegId:       info_d = {de_pkg::CtrlIdMagic, 4'(NumCh), 4'(NumBuf),
                                         16'(ArrayLatency)};
      de_pkg::CtrlRegAlignErr: info_d = {31'h0, align_err_q};
      default: info_d = 32'h0;
    endcase
  end

  always_comb begin
    unique case (reg_ch_q)
      2'd0:    reg_rdata_o = mon_rdata[0];
      2'd1:    reg_rdata_o = mon_rdata[1];
      2'd2:    reg_rdata_o = mon_rdata[2];
      default: reg_rdata_o = info_q;
    endcase
  end

  // ---------------------------------------------------------------------------------
  // Output stage. de from channel 0 is already delayed by 1 + ArrayLatency, i.e. it is
  // high exactly in the cycles in which pix_i carries columns 0 .. HActive-1.
  logic [NumCh-1:0][11:0] rgb_d, rgb_q;
  logic [NumCh-1:0][7:0]  rgb8_d, rgb8_q;
  logic                   hsync_d, hsync_q, vsync_d, vsync_q, blank_d, blank_q;
  logic [2:0]             w;

  // Windows above bits [11:4] do not exist; larger shifts act as 4.
  assign w = (out8_shift_i > 3'd4) ? 3'd4 : out8_shift_i;

  always_comb begin
    rgb_d   = '0;
    rgb8_d  = '0;
    hsync_d = ch_hsync[0];
    vsync_d = ch_vsync[0];
    blank_d = ~ch_de[0];
    for (int unsigned c = 0; c < NumCh; c++) begin
      logic [11:0] sh;
      sh = pix_i[c] >> w;
      if (ch_de[0]) begin
        rgb_d[c] = pix_i[c];
        // Saturation reads the pixel as two's complement (docs/isa.md §1: the top bits
        // may serve as sign and overflow bits when 8 bits per colour are enough).
        if (!out8_sat_i)        rgb8_d[c] = sh[7:0];
        else if (pix_i[c][11])  rgb8_d[c] = 8'h00;
        else if (sh[11:8] != '0) rgb8_d[c] = 8'hFF;
        else                    rgb8_d[c] = sh[7:0];
      end
    end
    // A pixel slot without a pixel: HActive exceeds the PEs in use, or ArrayLatency is
    // wrong for the array that is connected.
    align_err_d = align_err_q | (ch_de[0] & ~(&pix_valid_i));
  end

  always_ff @(posedge clk_i) begin
    if (rst_i) begin
      rgb_q       <= '0;
      rgb8_q      <= '0;
      blank_q     <= 1'b1;
      align_err_q <= 1'b0;
      reg_ch_q    <= '0;
      info_q      <= '0;
    end else begin
      rgb_q       <= rgb_d;
      rgb8_q      <= rgb8_d;
      blank_q     <= blank_d;
      align_err_q <= align_err_d;
      reg_ch_q    <= reg_ch_d;
      info_q      <= info_d;
    end
  end

  // Not reset: during reset they follow the access controller's inactive levels, whose
  // polarity depends on the mode.
  always_ff @(posedge clk_i) begin
    hsync_q <= hsync_d;
    vsync_q <= vsync_d;
  end

  assign rgb_o       = rgb_q;
  assign rgb8_o      = rgb8_q;
  assign hsync_o     = hsync_q;
  assign vsync_o     = vsync_q;
  assign blank_o     = blank_q;
  assign align_err_o = align_err_q;

endmodule

`default_nettype wire
