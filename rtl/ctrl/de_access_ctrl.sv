// Difference Engine - Access Controller (Kuijk 1995 §7.5; design in
// docs/display-controller.md).
//
// * Issues the Refresh at h = 0 of every line (active and blank), so Refreshes are
//   exactly one line time apart.
// * Between Refreshes (h = 1 .. HTotal-1 of line v) the window belongs to line v+1.
//   If line v+1 is active the bus is granted to the Instruction Buffers, one whole
//   command at a time, round-robin (§7.5 NEXT = the grant moving on, WRITE = the
//   per-slot strobe grant_o); slots nobody fills carry Nop. Windows of blank lines
//   carry only Nop.
// * Each buffer's stream is a sequence of lines, each ended by a marker (identifier
//   0x100, never put on the bus); the k-th marker ends the buffer's part of the k-th
//   active line. A buffer that has not reached its marker when the Refresh must go is
//   late: it is not granted again until it has discarded (drain) the rest of that line
//   up to and including the marker. Discarded words are reported on drop_o.
// * hsync/vsync/de are delayed by 1 + ArrayLatency so that they line up with column 0
//   of a line leaving the array ArrayLatency cycles after its Refresh is on instr_o.
`default_nettype none

module de_access_ctrl #(
  parameter int unsigned NumBuf       = 4,
  parameter int unsigned ArrayLatency = 3,
  parameter int unsigned SkipW        = 8,
  // Mode 3's geometry (de_video_timing).
  parameter de_pkg::video_mode_t TestMode = de_pkg::VideoTestDefault,
  localparam int unsigned IdxW        = (NumBuf > 1) ? $clog2(NumBuf) : 1
) (
  input  logic                         clk_i,
  input  logic                         rst_i,
  input  logic [1:0]                   mode_i,
  // Instruction Buffer read sides.
  input  logic [NumBuf-1:0]            buf_valid_i,
  input  logic [NumBuf-1:0][de_pkg::RecW-1:0]      buf_data_i,
  output logic [NumBuf-1:0]            buf_ready_o,
  output logic [NumBuf-1:0]            buf_drain_o,
  // Instruction bus into PE 0 (registered; one instruction every clock).
  output logic [de_pkg::RecW-1:0]                  instr_o,
  output logic [NumBuf-1:0]            grant_o,        // who drives instr_o this cycle
  // Video signals aligned with the array's pixel output.
  output logic                         hsync_o,
  output logic                         vsync_o,
  output logic                         de_o,
  // Synchronisation for the y-processors (issue time base, registered with instr_o).
  output logic [11:0]                  line_o,          // line whose window is open
  output logic                         window_o,        // window of an active line open
  output logic [NumBuf-1:0]            done_o,          // buffer delivered its line
  output logic [NumBuf-1:0]            late_o,          // buffer is discarding a line
  // Events for the Load Monitor (registered with instr_o).
  output logic                         ev_refresh_o,    // instr_o is a Refresh
  output logic                         ev_line_active_o,// ... of an active line
  output logic [11:0]                  ev_line_o,       // ... of this line
  output logic                         ev_last_line_o,  // ... the last active line
  output logic [NumBuf-1:0]            ev_late_o,       // ... and these buffers were late
  output logic                         ev_issue_o,      // instr_o came from a buffer
  output logic                         ev_free_o,       // Nop in an active line's window
  output logic [NumBuf-1:0]            drop_o           // a word was discarded
);

  localparam int unsigned PipeLen   = ArrayLatency + 1;

  // Parameter checks at elaboration.
  if (NumBuf < 1 || NumBuf > 8) begin : g_bad_numbuf
    $fatal(1, "de_access_ctrl: NumBuf must be 1..8");
  end
  if (ArrayLatency > 4095) begin : g_bad_latency
    $fatal(1, "de_access_ctrl: ArrayLatency must be < 4096");
  end
  if (SkipW < 2 || SkipW > 16) begin : g_bad_skipw
    $fatal(1, "de_access_ctrl: SkipW must be 2..16");
  end

  // ---------------------------------------------------------------------------------
  // Timing.
  logic [11:0] h, v, h_total, v_total, v_active, next_line;
  logic        t_hsync, t_vsync, t_de, line_start, next_active, hpol, vpol;

  de_video_timing #(.TestMode(TestMode)) u_timing (
    .clk_i, .rst_i, .mode_i,
    .h_o(h), .v_o(v), .h_total_o(h_total), .v_total_o(v_total), .v_active_o(v_active),
    .hsync_o(t_hsync), .vsync_o(t_vsync), .de_o(t_de), .hpol_o(hpol), .vpol_o(vpol),
    .line_start_o(line_start), .next_active_o(next_active), .next_line_o(next_line)
  );

  // ---------------------------------------------------------------------------------
  // Per-buffer head decode.
  logic [NumBuf-1:0] head_start, head_marker, skipping;
  logic [NumBuf-1:0] done_d, done_q;
  logic [NumBuf-1:0][SkipW-1:0] skip_d, skip_q;

  for (genvar i = 0; i < NumBuf; i++) begin : g_head
    assign head_start[i]  = de_pkg::id_starts_cmd(de_pkg::rec_id(buf_data_i[i]));
    assign head_marker[i] = (de_pkg::rec_id(buf_data_i[i]) == de_pkg::IdRefresh);
    assign skipping[i]    = (skip_q[i] != '0);
  end

  logic [IdxW-1:0]   owner_d, owner_q;
  logic              win;        // a slot of an active line's window
  logic              cont;       // owner is in the middle of a command
  logic              issue;
  logic [IdxW-1:0]   sel;
  logic [NumBuf-1:0] elig, mk_pop, grant, late_now, drop;

  assign win = ~line_start & next_active;

  // The line refreshed at h = 0 of line v is v itself; its window was the previous line.
  logic next_line_is_refreshed_active;
  assign next_line_is_refreshed_active = (v < v_active);

  always_comb begin
    // A buffer may start a command when its committed head is a command start, it has
    // not delivered this line yet and it is not discarding an earlier line.
    for (int unsigned i = 0; i < NumBuf; i++) begin
      elig[i] = buf_valid_i[i] & head_start[i] & ~head_marker[i] & ~done_q[i] &
                ~skipping[i];
    end
  end

  // Only the owner can have a continuation slot at its head: commands are granted
  // whole, and a command cut by the Refresh makes its buffer late (discarding).
  assign cont = buf_valid_i[owner_q] & ~head_start[owner_q] & ~done_q[owner_q] &
                ~skipping[owner_q];

  logic [IdxW:0] rr_idx;

  always_comb begin
    rr_idx  = '0;
    issue   = 1'b0;
    sel     = owner_q;
    owner_d = owner_q;
    if (win) begin
      if (cont) begin
        issue = 1'b1;
      end else begin
        // Round-robin: the first eligible buffer after the current owner.
        for (int unsigned k = NumBuf; k >= 1; k--) begin
          rr_idx = (IdxW + 1)'(owner_q) + (IdxW + 1)'(k);
          if (rr_idx >= (IdxW + 1)'(NumBuf)) rr_idx = rr_idx - (IdxW + 1)'(NumBuf);
          if (elig[rr_idx[IdxW-1:0]]) begin
            issue = 1'b1;
            sel   = rr_idx[IdxW-1:0];
          end
        end
        owner_d = sel;
      end
    end
  end

  always_comb begin
    grant    = '0;
    mk_pop   = '0;
    late_now = '0;
    drop     = '0;
    done_d   = done_q;
    skip_d   = skip_q;
    if (issue) grant[sel] = 1'b1;
    for (int unsigned i = 0; i < NumBuf; i++) begin
      // A buffer whose head is its line marker delivers it without using a bus slot.
      mk_pop[i] = win & buf_valid_i[i] & head_marker[i] & ~done_q[i] & ~skipping[i];
      if (mk_pop[i]) done_d[i] = 1'b1;
      // Discarding: every word up to and including the marker of the late line.
      if (skipping[i] && buf_valid_i[i]) begin
        if (head_marker[i]) begin
          skip_d[i] = skip_q[i] - 1'b1;
        end else begin
          drop[i] = 1'b1;
        end
      end
      if (line_start) begin
        // The Refresh closes the window: a buffer that has not delivered is late.
        if (next_line_is_refreshed_active && !done_q[i]) begin
          late_now[i] = 1'b1;
          // Saturates: a y-processor 2^SkipW-1 lines behind has lost sync (host resets).
          if (skip_d[i] != '1) skip_d[i] = skip_d[i] + 1'b1;
        end
        done_d[i] = 1'b0;
      end
    end
  end

  for (genvar i = 0; i < NumBuf; i++) begin : g_ready
    assign buf_ready_o[i] = grant[i] | mk_pop[i] | skipping[i];
    assign buf_drain_o[i] = skipping[i];
  end

  // ---------------------------------------------------------------------------------
  // Registered bus and events.
  logic [de_pkg::RecW-1:0]       instr_d, instr_q;
  logic [NumBuf-1:0] grant_q, late_q, drop_q;
  logic [11:0]       line_q, ev_line_q;
  logic              window_q, ev_refresh_q, ev_active_q, ev_last_q, ev_issue_q, ev_free_q;

  always_comb begin
    instr_d = 48'h0;  // Nop
    if (line_start) begin
      instr_d = {de_pkg::IdRefresh, {de_pkg::DataW{1'b0}}};
    end else if (issue) begin
      instr_d = buf_data_i[sel];
    end
  end

  always_ff @(posedge clk_i) begin
    if (rst_i) begin
      owner_q      <= '0;
      done_q       <= '0;
      skip_q       <= '0;
      instr_q      <= '0;
      grant_q      <= '0;
      late_q       <= '0;
      drop_q       <= '0;
      line_q       <= '0;
      ev_line_q    <= '0;
      window_q     <= 1'b0;
      ev_refresh_q <= 1'b0;
      ev_active_q  <= 1'b0;
      ev_last_q    <= 1'b0;
      ev_issue_q   <= 1'b0;
      ev_free_q    <= 1'b0;
    end else begin
      owner_q      <= owner_d;
      done_q       <= done_d;
      skip_q       <= skip_d;
      instr_q      <= instr_d;
      grant_q      <= grant;
      late_q       <= late_now;
      drop_q       <= drop;
      line_q       <= next_line;
      ev_line_q    <= v;
      window_q     <= win;
      ev_refresh_q <= line_start;
      ev_active_q  <= line_start & next_line_is_refreshed_active;
      ev_last_q    <= line_start & (v == v_active - 12'd1);
      ev_issue_q   <= issue;
      ev_free_q    <= win & ~issue;
    end
  end

  assign instr_o          = instr_q;
  assign grant_o          = grant_q;
  assign line_o           = line_q;
  assign window_o         = window_q;
  assign done_o           = done_q;
  assign late_o           = skipping;
  assign ev_refresh_o     = ev_refresh_q;
  assign ev_line_active_o = ev_active_q;
  assign ev_line_o        = ev_line_q;
  assign ev_last_line_o   = ev_last_q;
  assign ev_late_o        = late_q;
  assign ev_issue_o       = ev_issue_q;
  assign ev_free_o        = ev_free_q;
  assign drop_o           = drop_q;

  // ---------------------------------------------------------------------------------
  // Sync/blank delay: 1 cycle for instr_q plus the array's latency.
  logic [PipeLen-1:0][2:0] vid_d, vid_q;

  always_comb begin
    vid_d = vid_q;
    vid_d[0] = {t_hsync, t_vsync, t_de};
    for (int unsigned i = 1; i < PipeLen; i++) begin
      vid_d[i] = vid_q[i-1];
    end
  end

  always_ff @(posedge clk_i) begin
    if (rst_i) begin
      vid_q <= '0;
    end else begin
      vid_q <= vid_d;
    end
  end

  // The pipeline carries active-high pulses (reset = inactive); polarity is applied last.
  assign hsync_o = vid_q[PipeLen-1][2] ~^ hpol;
  assign vsync_o = vid_q[PipeLen-1][1] ~^ vpol;
  assign de_o    = vid_q[PipeLen-1][0];

  // h, h_total and v_total are used by the formal properties only.
  logic unused_totals;
  assign unused_totals = ^{h, h_total, v_total};

`ifdef FORMAL
  // Properties checked by tb/formal/de_access_ctrl.sby (test mode, mode_i = 3).
  logic        f_past_valid = 1'b0;
  logic [15:0] f_since_refresh;
  logic        f_seen_refresh;

  always_ff @(posedge clk_i) begin
    f_past_valid <= 1'b1;
    if (rst_i) begin
      f_since_refresh <= '0;
      f_seen_refresh  <= 1'b0;
    end else if (de_pkg::rec_id(instr_d) == de_pkg::IdRefresh) begin
      f_since_refresh <= '0;
      f_seen_refresh  <= 1'b1;
    end else begin
      f_since_refresh <= f_since_refresh + 1'b1;
    end
  end

  always_comb begin
    if (!f_past_valid) assume (rst_i);
    assume (mode_i == 2'd3);
    // The buffers behave as FIFO read ports: a valid head stays until it is taken.
    if (f_past_valid && !rst_i) begin
      // At most one buffer owns the bus; an owner is always a valid buffer.
      assert ($onehot0(grant));
      if (issue) assert (buf_valid_i[sel] && buf_ready_o[sel]);
      // The Refresh is only ever issued at h = 0, and buffers never at h = 0.
      assert ((de_pkg::rec_id(instr_d) == de_pkg::IdRefresh) == line_start);
      if (line_start) assert (grant == '0);
      // Refresh spacing is constant: exactly one line time.
      if (f_seen_refresh) begin
        if (h == 12'd0) assert (f_since_refresh + 16'd1 == 16'(h_total));
        else            assert (f_since_refresh + 16'd1 == 16'(h));
      end else begin
        // Only the first cycle after reset has not seen a Refresh yet.
        assert (h == 12'd0 && f_since_refresh == '0);
      end
      assert (32'(owner_q) < NumBuf);
      assert (h_total == TestMode.h_act + TestMode.h_fp + TestMode.h_sync + TestMode.h_bp);
      assert (v_total == TestMode.v_act + TestMode.v_fp + TestMode.v_sync + TestMode.v_bp);
      assert (h < h_total && v < v_total);
    end
  end
`endif

endmodule

`default_nettype wire
