// The board's SDRAM frame store (docs/board.md §4, docs/sdram-frames-spec.md): frames
// as tables of lines in SDRAM, played into the display controller's three instruction
// buffers.
//
//   pixel clock (clk_i)          |  SDRAM clock (clk_sdram_i, 125 MHz)
//                                |
//   loader cmd_* -> [cmd FIFO] --+--> X: word write ----------------------+
//   (X / F / Q, in order)        |    F: slot RAM of the colour           |
//                                |    Q: pending sequence -> sequencer    v
//                                |                 | frame_go     arbiter (round robin,
//                                |  de_frame_fetch R/G/B -- requests --> 1 register)
//                                |       ^   |                            |
//                                |       |   +--- words --+          de_sdram_ctrl <-> pins
//   de_frame_player R/G/B <- [prefetch FIFO 2048 x 36] <---+   <- read data (tag = colour)
//   -> wr_* (display controller) |
//
// Frame slots: 64 per colour, {table offset, window, compensation} (F), each with a
// "defined" bit (an undefined slot plays as a black frame). The sequence (Q: first,
// count, hold, loop) is one for all three colours. The sequencer is a barrier: when all
// three fetchers are at a frame boundary it picks the frame's slot (a pending Q replaces
// the sequence here, so a switch happens only at a frame boundary), reads the three
// colours' slots and starts all three together, three clocks later. So the colours fetch the same frame
// number from the same sequence position: they stay in lockstep, and since every fetched
// frame is played in order (exactly VActive markers each), a slot is shown for exactly
// `hold` displayed frames. Before any Q, and after reset, the frames are black.
//
// The colour waiting at the barrier cannot starve: it waits only while another colour's
// prefetch FIFO is full of the same frame, that is while the display is at least a
// FIFO's depth (>= 2.5 lines at 640x480) before that frame's end.
//
// Resets: rst_i is the pixel domain's synchronous reset; the SDRAM domain gets it
// through a two-flip-flop synchroniser (rst_sd), so it is asserted a few SDRAM clocks
// later and released a few SDRAM clocks after it (both FIFOs' sides are in reset at the
// same time, and the pixel side's first reads find them empty).
`default_nettype none

module de_sdram_frames #(
  parameter int unsigned PfDepth   = 2048,     // prefetch FIFO words per colour
  parameter int unsigned CmdDepth  = 16,       // loader commands in flight
  parameter int unsigned SdTckPs   = 8000,     // the SDRAM clock's period
  parameter int unsigned SdTinitNs = 100_000,  // power-up wait (simulations shorten it)
  localparam int unsigned PW = $clog2(PfDepth)
) (
  input  logic             clk_i,
  input  logic             rst_i,
  input  logic             clk_sdram_i,
  input  logic [11:0]      vactive_i,        // quasi-static (the video mode)
  // Loader commands (pixel clock), de_loader's encoding.
  input  logic             cmd_valid_i,
  output logic             cmd_ready_o,
  input  logic [56:0]      cmd_i,
  // Display controller write ports (pixel clock).
  output logic [2:0]       wr_valid_o,
  input  logic [2:0]       wr_ready_i,
  output logic [2:0][47:0] wr_data_o,
  input  logic [2:0]       dc_late_i,        // the display controller discards a late line
  // Status (pixel clock).
  output logic             frame_o,          // colour R's player finished a frame
  output logic             q_pending_o,      // a sequence waits for a frame boundary
  output logic [7:0]       malformed_o,      // lines fixed by the fetchers (saturating)
  output logic [7:0]       late_o,           // late lines for want of data (saturating)
  output logic             sd_init_done_o,
  // SDRAM pins (SDRAM clock; docs/sdram-frames-spec.md §4).
  output de_sdram_pkg::sdram_out_t sd_o,
  input  logic [15:0]      sd_dq_i
);
  if (PfDepth < 16 || PfDepth > 8192 || (PfDepth & (PfDepth - 1)) != 0) begin : g_bad_pf
    $fatal(1, "de_sdram_frames: PfDepth must be a power of two, 16..8192");
  end

  localparam int unsigned NumCh = 3;
  // Command encoding (de_loader): [56:55] type.
  localparam logic [1:0] TypX = 2'd1, TypF = 2'd2, TypQ = 2'd3;

  // ---------------------------------------------------------------- reset, quasi-statics
  (* ASYNC_REG = "TRUE" *) logic [1:0] rst_sync_q;
  logic        rst_sd;
  (* ASYNC_REG = "TRUE" *) logic [11:0] vact_s1_q, vact_s2_q;
  always_ff @(posedge clk_sdram_i) begin
    rst_sync_q <= {rst_sync_q[0], rst_i};
    vact_s1_q  <= vactive_i;
    vact_s2_q  <= vact_s1_q;
  end
  assign rst_sd = rst_sync_q[1];

  // ---------------------------------------------------------------- command FIFO
  logic        cq_valid, cq_ready;
  logic [56:0] cq;
  /* verilator lint_off UNUSEDSIGNAL */  // free count: the loader checks ready only
  logic [$clog2(CmdDepth):0] cq_free;
  /* verilator lint_on UNUSEDSIGNAL */

  de_async_fifo #(.Width(57), .Depth(CmdDepth)) u_cmd_fifo (
    .wclk_i(clk_i), .wrst_i(rst_i), .wvalid_i(cmd_valid_i), .wready_o(cmd_ready_o),
    .wdata_i(cmd_i), .wfree_o(cq_free),
    .rclk_i(clk_sdram_i), .rrst_i(rst_sd), .rvalid_o(cq_valid), .rready_i(cq_ready),
    .rdata_o(cq)
  );

  logic [1:0]  cq_type;
  logic [1:0]  cq_ch;
  assign cq_type = cq[56:55];
  assign cq_ch   = cq[54:53];

  // ---------------------------------------------------------------- slots
  typedef struct packed {
    logic [18:0] tbl;      // table offset / 4
    logic [2:0]  win;
    logic        comp;
  } slot_t;

  slot_t [NumCh-1:0]       slot_rd;
  logic  [NumCh-1:0][63:0] slot_def_q;
  logic  [5:0]             slot_sel_q;
  logic                    f_write;
  assign f_write = cq_valid && cq_type == TypF;

  for (genvar c = 0; c < NumCh; c++) begin : g_slots
    slot_t slot_mem_q [64];
    always_ff @(posedge clk_sdram_i) begin
      if (f_write && cq_ch == 2'(c)) slot_mem_q[cq[52:47]] <= '{tbl: cq[46:28],
                                                              win: cq[25:23], comp: cq[22]};
    end
    assign slot_rd[c] = slot_mem_q[slot_sel_q];
    always_ff @(posedge clk_sdram_i) begin
      if (rst_sd)                          slot_def_q[c] <= '0;
      else if (f_write && cq_ch == 2'(c))  slot_def_q[c][cq[52:47]] <= 1'b1;
    end
  end

  // ---------------------------------------------------------------- sequencer
  typedef struct packed {
    logic [5:0] first;
    logic [6:0] count;
    logic [7:0] hold;
    logic       loop;
  } seq_t;

  // Three steps per frame boundary, each on flip-flops (a boundary comes at most once
  // per VActive lines): A, all three fetchers wait: a pending Q becomes the sequence;
  // B, the frame's slot (first + idx) and the advance flags; C, the slots are read and
  // all three fetchers start (go), and the position moves on for the next frame.
  typedef enum logic [1:0] {QIdle, QSel, QGo} qstate_e;

  qstate_e    qs_d, qs_q;
  seq_t       seq_d, seq_q, pend_d, pend_q;
  logic       seq_v_d, seq_v_q, pend_v_d, pend_v_q;
  logic [6:0] idx_d, idx_q;
  logic [7:0] hc_d, hc_q;
  logic       use_d, use_q, hold_done_d, hold_done_q, last_d, last_q;
  logic [5:0] slot_sel_d;
  logic [NumCh-1:0] f_wait;
  logic       go;

  assign go = (qs_q == QGo);

  always_comb begin
    qs_d        = qs_q;
    seq_d       = seq_q;
    seq_v_d     = seq_v_q;
    pend_d      = pend_q;
    pend_v_d    = pend_v_q;
    idx_d       = idx_q;
    hc_d        = hc_q;
    use_d       = use_q;
    slot_sel_d  = slot_sel_q;
    hold_done_d = hold_done_q;
    last_d      = last_q;
    unique case (qs_q)
      QIdle: begin
        if (&f_wait) begin
          qs_d = QSel;
          if (pend_v_q) begin
            seq_d    = pend_q;
            seq_v_d  = 1'b1;
            pend_v_d = 1'b0;
            idx_d    = 7'd0;
            hc_d     = 8'd0;
          end
        end
      end
      QSel: begin
        qs_d        = QGo;
        use_d       = seq_v_q;
        slot_sel_d  = seq_q.first + 6'(idx_q);
        hold_done_d = (9'(hc_q) + 9'd1 >= 9'(seq_q.hold));
        last_d      = (8'(idx_q) + 8'd1 >= 8'(seq_q.count));
      end
      QGo: begin
        qs_d = QIdle;
        if (hold_done_q) begin
          hc_d  = 8'd0;
          idx_d = last_q ? (seq_q.loop ? 7'd0 : idx_q) : idx_q + 7'd1;
        end else begin
          hc_d  = hc_q + 8'd1;
        end
      end
      default: qs_d = QIdle;
    endcase
    // A Q arriving now waits for the next boundary.
    if (cq_valid && cq_type == TypQ) begin
      pend_v_d = 1'b1;
      pend_d   = '{first: cq[52:47], count: cq[46:40], hold: cq[39:32], loop: cq[31]};
    end
  end

  always_ff @(posedge clk_sdram_i) begin
    if (rst_sd) begin
      qs_q        <= QIdle;
      seq_q       <= '0;
      seq_v_q     <= 1'b0;
      pend_q      <= '0;
      pend_v_q    <= 1'b0;
      idx_q       <= 7'd0;
      hc_q        <= 8'd0;
      use_q       <= 1'b0;
      slot_sel_q  <= 6'd0;
      hold_done_q <= 1'b0;
      last_q      <= 1'b0;
    end else begin
      qs_q        <= qs_d;
      seq_q       <= seq_d;
      seq_v_q     <= seq_v_d;
      pend_q      <= pend_d;
      pend_v_q    <= pend_v_d;
      idx_q       <= idx_d;
      hc_q        <= hc_d;
      use_q       <= use_d;
      slot_sel_q  <= slot_sel_d;
      hold_done_q <= hold_done_d;
      last_q      <= last_d;
    end
  end

  // ---------------------------------------------------------------- fetchers
  logic [NumCh-1:0]        req_v, grant, rd_v, pf_push, pf_ready, malformed;
  logic [NumCh-1:0][20:0]  req_off;
  logic [NumCh-1:0][35:0]  pf_wdata, pf_rdata;
  logic [NumCh-1:0][PW:0]  pf_free;
  logic [NumCh-1:0]        pf_rvalid, pf_take;
  logic                    ctl_rd_valid;
  logic [31:0]             ctl_rd_data;
  logic [1:0]              ctl_rd_tag;

  for (genvar c = 0; c < NumCh; c++) begin : g_ch
    assign rd_v[c] = ctl_rd_valid && ctl_rd_tag == 2'(c);

    de_frame_fetch #(.PfDepth(PfDepth)) u_fetch (
      .clk_i       (clk_sdram_i),
      .rst_i       (rst_sd),
      .vactive_i   (vact_s2_q),
      .frame_wait_o(f_wait[c]),
      .frame_go_i  (go),
      .slot_valid_i(use_q && slot_def_q[c][slot_sel_q]),
      .table4_i    (slot_rd[c].tbl),
      .window_i    (slot_rd[c].win),
      .comp_i      (slot_rd[c].comp),
      .req_valid_o (req_v[c]),
      .req_off_o   (req_off[c]),
      .req_grant_i (grant[c]),
      .rd_valid_i  (rd_v[c]),
      .rd_data_i   (ctl_rd_data),
      .pf_push_o   (pf_push[c]),
      .pf_data_o   (pf_wdata[c]),
      .pf_free_i   (pf_free[c]),
      .malformed_o (malformed[c])
    );

    de_async_fifo #(.Width(36), .Depth(PfDepth)) u_pf (
      .wclk_i(clk_sdram_i), .wrst_i(rst_sd), .wvalid_i(pf_push[c]), .wready_o(pf_ready[c]),
      .wdata_i(pf_wdata[c]), .wfree_o(pf_free[c]),
      .rclk_i(clk_i), .rrst_i(rst_i), .rvalid_o(pf_rvalid[c]), .rready_i(pf_take[c]),
      .rdata_o(pf_rdata[c])
    );
  end

  // ---------------------------------------------------------------- arbiter
  // Requesters 0..2: the colours' 4-word reads; 3: the loader's word writes (X). Round
  // robin; the winner goes into one output register, which the controller accepts
  // (its ready depends on its own state only), so no multiplexer sits in front of the
  // controller's decision.
  logic        wreq_v;
  logic [3:0]  want, win_oh;
  logic [1:0]  rr_d, rr_q;
  logic        out_v_d, out_v_q, out_wr_d, out_wr_q, load, accepted;
  logic [22:0] out_addr_d, out_addr_q;
  logic [1:0]  out_tag_d, out_tag_q;
  logic [31:0] out_data_d, out_data_q;
  logic        ctl_wr_ready, ctl_rd_ready;

  assign wreq_v   = cq_valid && cq_type == TypX;
  assign want     = {wreq_v, req_v};
  assign accepted = out_v_q && (out_wr_q ? ctl_wr_ready : ctl_rd_ready);
  assign load     = !out_v_q || accepted;

  always_comb begin
    logic [1:0] k;
    k          = 2'd0;
    win_oh     = 4'b0000;
    rr_d       = rr_q;
    out_v_d    = out_v_q && !accepted;
    out_wr_d   = out_wr_q;
    out_addr_d = out_addr_q;
    out_tag_d  = out_tag_q;
    out_data_d = out_data_q;
    if (load) begin
      for (int i = 1; i <= 4; i++) begin
        k = rr_q + 2'(i);
        if (want[k] && win_oh == 4'b0000) win_oh[k] = 1'b1;
      end
      for (int i = 0; i < 4; i++) begin
        if (win_oh[i]) begin
          rr_d       = 2'(i);
          out_v_d    = 1'b1;
          out_wr_d   = (i == 3);
          out_tag_d  = 2'(i);
          out_addr_d = (i == 3) ? {cq_ch, cq[52:32]} : {2'(i), req_off[i]};
          out_data_d = cq[31:0];
        end
      end
    end
  end
  assign grant = win_oh[2:0];

  // The command FIFO's head leaves when it is done: X when granted, F and Q at once.
  assign cq_ready = cq_valid && (cq_type == TypX ? win_oh[3] : 1'b1);

  always_ff @(posedge clk_sdram_i) begin
    if (rst_sd) begin
      rr_q       <= 2'd3;
      out_v_q    <= 1'b0;
      out_wr_q   <= 1'b0;
      out_addr_q <= '0;
      out_tag_q  <= 2'd0;
      out_data_q <= 32'd0;
    end else begin
      rr_q       <= rr_d;
      out_v_q    <= out_v_d;
      out_wr_q   <= out_wr_d;
      out_addr_q <= out_addr_d;
      out_tag_q  <= out_tag_d;
      out_data_q <= out_data_d;
    end
  end

  /* verilator lint_off UNUSEDSIGNAL */  // last-word flag and refresh strobe: not needed here
  logic ctl_rd_last, ctl_refresh;
  /* verilator lint_on UNUSEDSIGNAL */

  de_sdram_ctrl #(.TckPs(SdTckPs), .CasLatency(3), .TinitNs(SdTinitNs)) u_ctrl (
    .clk_i         (clk_sdram_i),
    .rst_i         (rst_sd),
    .wr_valid_i    (out_v_q && out_wr_q),
    .wr_ready_o    (ctl_wr_ready),
    .wr_addr_i     (out_addr_q),
    .wr_data_i     (out_data_q),
    .rd_req_valid_i(out_v_q && !out_wr_q),
    .rd_req_ready_o(ctl_rd_ready),
    .rd_req_addr_i (out_addr_q),
    .rd_req_tag_i  (out_tag_q),
    .rd_valid_o    (ctl_rd_valid),
    .rd_data_o     (ctl_rd_data),
    .rd_tag_o      (ctl_rd_tag),
    .rd_last_o     (ctl_rd_last),
    .init_done_o   (sd_init_done_o),
    .refresh_o     (ctl_refresh),
    .sd_o, .sd_dq_i
  );

  // ---------------------------------------------------------------- status across
  // Malformed lines: a saturating count in Gray code (it changes by one bit per clock at
  // most: the words come one per 2 clocks, so at most one line ends per clock), read in
  // the pixel domain through two flip-flops.
  logic [7:0] mal_bin_d, mal_bin_q, mal_gray_q;
  (* ASYNC_REG = "TRUE" *) logic [7:0] mal_s1_q, mal_s2_q;
  (* ASYNC_REG = "TRUE" *) logic [1:0] pend_s_q;
  assign mal_bin_d = (|malformed && mal_bin_q != 8'hFF) ? mal_bin_q + 8'd1 : mal_bin_q;
  always_ff @(posedge clk_sdram_i) begin
    if (rst_sd) begin
      mal_bin_q  <= 8'd0;
      mal_gray_q <= 8'd0;
    end else begin
      mal_bin_q  <= mal_bin_d;
      mal_gray_q <= mal_bin_d ^ (mal_bin_d >> 1);
    end
  end
  always_ff @(posedge clk_i) begin
    mal_s1_q <= mal_gray_q;
    mal_s2_q <= mal_s1_q;
    pend_s_q <= {pend_s_q[0], pend_v_q};
  end
  function automatic logic [7:0] gray2bin8(logic [7:0] g);
    logic [7:0] b;
    b[7] = g[7];
    for (int i = 6; i >= 0; i--) b[i] = b[i + 1] ^ g[i];
    return b;
  endfunction
  assign malformed_o = gray2bin8(mal_s2_q);
  assign q_pending_o = pend_s_q[1];

  // ---------------------------------------------------------------- players (pixel clock)
  logic [NumCh-1:0] frame, starve;
  for (genvar c = 0; c < NumCh; c++) begin : g_play
    de_frame_player u_player (
      .clk_i, .rst_i,
      .vactive_i (vactive_i),
      .pf_valid_i(pf_rvalid[c]),
      .pf_ready_o(pf_take[c]),
      .pf_data_i (pf_rdata[c]),
      .wr_valid_o(wr_valid_o[c]),
      .wr_ready_i(wr_ready_i[c]),
      .wr_data_o (wr_data_o[c]),
      .dc_late_i (dc_late_i[c]),
      .frame_o   (frame[c]),
      .starve_o  (starve[c])
    );
  end

  logic [7:0] late_d, late_q;
  assign late_d = (|starve && late_q != 8'hFF) ? late_q + 8'd1 : late_q;
  always_ff @(posedge clk_i) begin
    if (rst_i) late_q <= 8'd0;
    else       late_q <= late_d;
  end

  assign frame_o = frame[0];
  assign late_o  = late_q;

  /* verilator lint_off UNUSEDSIGNAL */  // FIFO ready (credit), G/B frame pulses
  logic unused;
  assign unused = ^{pf_ready, frame[2:1]};
  /* verilator lint_on UNUSEDSIGNAL */
endmodule

`default_nettype wire
