// The board's SDRAM frame store (docs/board.md §4, docs/sdram.md §5,
// docs/sdram-frames-spec.md): frames as tables of lines in SDRAM, played into the
// display controller's three instruction buffers.
//
//   pixel clock (clk_i, 25 MHz)                     |  SDRAM clock (clk_sdram_i, 125 MHz)
//                                                   |
//   loader cmd_* --X--------------------> [X FIFO] -+-> X hold ----------------+
//            \--F--> slot RAMs R/G/B                 |                          v
//             \-Q--> sequencer (barrier)             |   R/G/B hold -> arbiter (X first,
//                       | frame_go                  |        ^        round robin, 1 reg)
//   de_frame_fetch R/G/B --requests--> [req FIFO x3] -+--------+            |  info FIFO
//        ^  credit: reserved - popped - dropped     |                de_sdram_ctrl <-> pins
//        +---------- table entries <-- [ent FIFO x3] <-+-- return: table words,   |
//        +---- dropped-word counts (Gray) <---------+   block words, pads <--- read data
//   de_frame_player R/G/B <-- [prefetch FIFO 2048 x 36 x3] <-- (registered push)
//   -> wr_* (display controller)                    |
//
// Which clock and why: the SDRAM side holds only what must keep up with the data bus
// (a 32-bit word every 2 SDRAM clocks): the controller, the arbiter with one output
// register, an in-order info FIFO (what each granted burst is: colour, table or block,
// which words belong, the line's last word), and the return path that writes the words
// into the entry and prefetch FIFOs. Everything that decides (the fetchers' tables,
// lines, credit; the slots; the sequencer) runs on the pixel clock, where a colour needs
// a 4-word burst at most every 4 clocks (all three together about one burst per 1.6
// pixel clocks): the table, line and credit arithmetic is off the 125 MHz paths.
//
// Frame slots: 64 per colour, {table offset, window, compensation} (F), each with a
// "defined" bit (an undefined slot plays as a black frame). The sequence (Q: first,
// count, hold, loop) is one for all three colours. The sequencer is a barrier: when all
// three fetchers are at a frame boundary it picks the frame's slot (a pending Q replaces
// the sequence here, so a switch happens only at a frame boundary), reads the three
// colours' slots and starts all three together, three clocks later. So the colours
// fetch the same frame number from the same sequence position: they stay in lockstep,
// and since every fetched frame is played in order (exactly VActive markers each), a
// slot is shown for exactly `hold` displayed frames. Before any Q, and after reset, the
// frames are black.
//
// Order of the loader's commands: X goes through the X FIFO to the SDRAM side; F and Q
// are taken on the pixel side only once every earlier X has left that FIFO, and the
// SDRAM side's arbiter serves an X before any read, so a frame's reads never overtake
// the writes of its table and blocks that came before its F and Q.
//
// The colour waiting at the barrier cannot starve: it waits only while another colour's
// prefetch FIFO is full of the same frame, that is while the display is at least a
// FIFO's depth (>= 2.5 lines at 640x480) before that frame's end.
//
// Resets: rst_i is the pixel domain's synchronous reset; the SDRAM domain gets it
// through a two-flip-flop synchroniser (rst_sd), so it is asserted a few SDRAM clocks
// later and released a few SDRAM clocks after it (both FIFOs' sides are in reset at the
// same time, and the pixel side's first reads find them empty). rst_i must last at
// least 3 pixel clocks (the board stretches it to 16).
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
  localparam logic [31:0] MarkerWord = 32'h0800_0000;   // LUT code 1 = REFRESH
  localparam int unsigned ReqW = 35;     // de_frame_fetch's request
  localparam int unsigned CW   = PW + 2; // dropped-word counts (de_frame_fetch's credit)
  localparam int unsigned ReqDepth = 4;  // requests queued per colour
  localparam int unsigned EntDepth = 8;  // table words reserved per colour
  localparam int unsigned EntFifo  = 16; // entry FIFO (twice: its write side's view lags)

  typedef struct packed {
    logic        tbl;
    logic        pad;
    logic [20:0] off;
    logic [3:0]  vmask;
    logic [3:0]  lmask;
    logic [2:0]  win;
    logic        comp;
  } req_t;

  function automatic logic [CW-1:0] gray2bin(logic [CW-1:0] g);
    logic [CW-1:0] b;
    b[CW-1] = g[CW-1];
    for (int i = int'(CW) - 2; i >= 0; i--) b[i] = b[i + 1] ^ g[i];
    return b;
  endfunction

  // ---------------------------------------------------------------- reset
  (* ASYNC_REG = "TRUE" *) logic [1:0] rst_sync_q;
  logic rst_sd;
  always_ff @(posedge clk_sdram_i) rst_sync_q <= {rst_sync_q[0], rst_i};
  assign rst_sd = rst_sync_q[1];

  // ================================================================ pixel clock side
  // ---------------------------------------------------------------- loader commands
  logic [1:0] cmd_type, cmd_ch;
  logic       x_wready, x_push, x_push_q, x_drained, f_write, q_take;
  logic [$clog2(CmdDepth):0] x_free;
  assign cmd_type  = cmd_i[56:55];
  assign cmd_ch    = cmd_i[54:53];
  // The X FIFO is empty as its write side sees it (its free count lags one push; it
  // reads CmdDepth during reset).
  assign x_drained = (32'(x_free) >= CmdDepth - 1) && !x_push_q;
  assign x_push    = cmd_valid_i && cmd_type == TypX && x_wready;
  assign f_write   = cmd_valid_i && cmd_type == TypF && x_drained;
  assign q_take    = cmd_valid_i && cmd_type == TypQ && x_drained;
  always_comb begin
    unique case (cmd_type)
      TypX:       cmd_ready_o = x_wready;
      TypF, TypQ: cmd_ready_o = x_drained;
      default:    cmd_ready_o = 1'b1;
    endcase
  end
  always_ff @(posedge clk_i) begin
    if (rst_i) x_push_q <= 1'b0;
    else       x_push_q <= x_push;
  end

  // ---------------------------------------------------------------- slots
  typedef struct packed {
    logic [18:0] tbl;      // table offset / 4
    logic [2:0]  win;
    logic        comp;
  } slot_t;

  slot_t [NumCh-1:0]       slot_rd;
  logic  [NumCh-1:0][63:0] slot_def_q;
  logic  [5:0]             slot_sel_q;

  for (genvar c = 0; c < NumCh; c++) begin : g_slots
    slot_t slot_mem_q [64];
    always_ff @(posedge clk_i) begin
      if (f_write && cmd_ch == 2'(c)) slot_mem_q[cmd_i[52:47]] <= '{tbl: cmd_i[46:28],
                                                                win: cmd_i[25:23],
                                                                comp: cmd_i[22]};
    end
    assign slot_rd[c] = slot_mem_q[slot_sel_q];
    always_ff @(posedge clk_i) begin
      if (rst_i)                            slot_def_q[c] <= '0;
      else if (f_write && cmd_ch == 2'(c))  slot_def_q[c][cmd_i[52:47]] <= 1'b1;
    end
  end

  // ---------------------------------------------------------------- sequencer
  typedef struct packed {
    logic [5:0] first;
    logic [6:0] count;
    logic [7:0] hold;
    logic       loop;
  } seq_t;

  // Three steps per frame boundary: A, all three fetchers wait: a pending Q becomes the
  // sequence; B, the frame's slot (first + idx) and the advance flags; C, the slots are
  // read and all three fetchers start (go), and the position moves on for the next frame.
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
    if (q_take) begin
      pend_v_d = 1'b1;
      pend_d   = '{first: cmd_i[52:47], count: cmd_i[46:40], hold: cmd_i[39:32],
                   loop: cmd_i[31]};
    end
  end

  always_ff @(posedge clk_i) begin
    if (rst_i) begin
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
  assign q_pending_o = pend_v_q;

  // ---------------------------------------------------------------- fetchers, FIFOs
  logic [NumCh-1:0]            fq_valid, fq_ready, ent_valid, ent_ready;
  logic [NumCh-1:0][ReqW-1:0]  fq_data;
  logic [NumCh-1:0][32:0]      ent_rdata;
  logic [NumCh-1:0]            pf_rvalid, pf_take;
  logic [NumCh-1:0][35:0]      pf_rdata;
  logic [NumCh-1:0][CW-1:0]    drop_bin_q;
  (* ASYNC_REG = "TRUE" *) logic [NumCh-1:0][CW-1:0] drop_s1_q, drop_s2_q;
  // SDRAM side of the FIFOs.
  logic [NumCh-1:0]            rq_valid, rq_ready, ent_push_q, pf_push_q;
  logic [NumCh-1:0][ReqW-1:0]  rq_data;
  logic [NumCh-1:0][32:0]      ent_wdata_q;
  logic [NumCh-1:0][35:0]      pf_wdata_q;
  logic [NumCh-1:0]            ent_wready, pf_wready;
  logic [NumCh-1:0][CW-1:0]    drop_gray_q;

  for (genvar c = 0; c < NumCh; c++) begin : g_ch
    // PfMargin 8: the FIFO's write side sees the player's pops some 3 SDRAM clocks and
    // a pixel clock late; 8 words cover that for any pixel clock up to the SDRAM clock.
    de_frame_fetch #(.PfDepth(PfDepth), .PfMargin(8), .EntDepth(EntDepth)) u_fetch (
      .clk_i,
      .rst_i,
      .vactive_i   (vactive_i),
      .frame_wait_o(f_wait[c]),
      .frame_go_i  (go),
      .slot_valid_i(use_q && slot_def_q[c][slot_sel_q]),
      .table4_i    (slot_rd[c].tbl),
      .window_i    (slot_rd[c].win),
      .comp_i      (slot_rd[c].comp),
      .req_valid_o (fq_valid[c]),
      .req_ready_i (fq_ready[c]),
      .req_o       (fq_data[c]),
      .ent_valid_i (ent_valid[c]),
      .ent_ready_o (ent_ready[c]),
      .ent_i       (ent_rdata[c]),
      .pf_pop_i    (pf_take[c] && pf_rvalid[c]),
      .pf_drop_i   (drop_bin_q[c])
    );

    /* verilator lint_off UNUSEDSIGNAL */  // free counts: credit is kept by the fetcher
    logic [$clog2(ReqDepth):0] fq_free;
    logic [$clog2(EntFifo):0]  ent_free;
    logic [PW:0]               pf_free;
    /* verilator lint_on UNUSEDSIGNAL */

    de_async_fifo #(.Width(ReqW), .Depth(ReqDepth)) u_req (
      .wclk_i(clk_i), .wrst_i(rst_i), .wvalid_i(fq_valid[c]), .wready_o(fq_ready[c]),
      .wdata_i(fq_data[c]), .wfree_o(fq_free),
      .rclk_i(clk_sdram_i), .rrst_i(rst_sd), .rvalid_o(rq_valid[c]), .rready_i(rq_ready[c]),
      .rdata_o(rq_data[c])
    );

    de_async_fifo #(.Width(33), .Depth(EntFifo)) u_ent (
      .wclk_i(clk_sdram_i), .wrst_i(rst_sd), .wvalid_i(ent_push_q[c]),
      .wready_o(ent_wready[c]), .wdata_i(ent_wdata_q[c]), .wfree_o(ent_free),
      .rclk_i(clk_i), .rrst_i(rst_i), .rvalid_o(ent_valid[c]), .rready_i(ent_ready[c]),
      .rdata_o(ent_rdata[c])
    );

    de_async_fifo #(.Width(36), .Depth(PfDepth)) u_pf (
      .wclk_i(clk_sdram_i), .wrst_i(rst_sd), .wvalid_i(pf_push_q[c]), .wready_o(pf_wready[c]),
      .wdata_i(pf_wdata_q[c]), .wfree_o(pf_free),
      .rclk_i(clk_i), .rrst_i(rst_i), .rvalid_o(pf_rvalid[c]), .rready_i(pf_take[c]),
      .rdata_o(pf_rdata[c])
    );

    // Dropped words across: a Gray count (one bit changes per SDRAM clock at most),
    // two flip-flops, then binary in a register of its own (one more clock of lag only
    // makes the fetcher's credit more conservative).
    always_ff @(posedge clk_i) begin
      if (rst_i) begin
        drop_s1_q[c]  <= '0;
        drop_s2_q[c]  <= '0;
        drop_bin_q[c] <= '0;
      end else begin
        drop_s1_q[c]  <= drop_gray_q[c];
        drop_s2_q[c]  <= drop_s1_q[c];
        drop_bin_q[c] <= gray2bin(drop_s2_q[c]);
      end
    end
  end

  // ---------------------------------------------------------------- players
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

  // ================================================================ SDRAM clock side
  // ---------------------------------------------------------------- X FIFO
  logic        xq_valid, xv_q;
  logic [54:0] xq_data, x_q;
  logic        x_take;

  de_async_fifo #(.Width(55), .Depth(CmdDepth)) u_x_fifo (
    .wclk_i(clk_i), .wrst_i(rst_i), .wvalid_i(cmd_valid_i && cmd_type == TypX),
    .wready_o(x_wready), .wdata_i(cmd_i[54:0]), .wfree_o(x_free),
    .rclk_i(clk_sdram_i), .rrst_i(rst_sd), .rvalid_o(xq_valid), .rready_i(!xv_q),
    .rdata_o(xq_data)
  );

  // ---------------------------------------------------------------- request holds
  // Each FIFO's head is taken into a hold register when that is empty, so the FIFO's
  // read side depends on one flip-flop only, not on the arbiter.
  req_t [NumCh-1:0] h_q;
  logic [NumCh-1:0] hv_q, hv_d, pad_go, want_d, want_q, pick, grant;
  logic [NumCh-1:0][2:0] outst_q, outst_d;  // granted reads whose last word is not back

  for (genvar c = 0; c < NumCh; c++) begin : g_hold
    assign rq_ready[c] = !hv_q[c];
    // A pad is written when every earlier read of its colour is back (its words are
    // then in the push register or in the FIFO), so it keeps its place in the stream.
    // (outst_q counts the grants up to the clock before; a pad is never granted.)
    assign pad_go[c]   = hv_q[c] && h_q[c].pad && (outst_q[c] == 3'd0);
  end

  // ---------------------------------------------------------------- arbiter
  // X first (the loader's words are rare, and a frame's reads must not overtake the
  // writes before its Q), then the colours round robin; the winner goes into one output
  // register, which the controller accepts (its ready depends on its own state only).
  // The register is loaded only when it is empty, so the choice depends on flip-flops
  // only (want_q: a read waits in the hold and the info FIFO has room, registered);
  // that costs no bandwidth: the controller takes its next request at the soonest two
  // clocks after the last one (the clock after it issued that one's READ).
  logic        out_v_d, out_v_q, out_wr_d, out_wr_q, load, accepted, win_x;
  logic [22:0] out_addr_d, out_addr_q;
  logic [1:0]  out_tag_d, out_tag_q;
  logic [31:0] out_data_d, out_data_q;
  logic [1:0]  rr_d, rr_q;              // the colour granted last
  logic        ctl_wr_ready, ctl_rd_ready;
  logic        info_room_d;

  assign accepted = out_v_q && (out_wr_q ? ctl_wr_ready : ctl_rd_ready);
  assign load     = !out_v_q;
  assign win_x = load && xv_q;

  // pick: the round robin's choice among the reads (registers only: the data paths
  // select with it); grant: pick when the register is loaded and no X goes first.
  always_comb begin
    unique case (rr_q)
      2'd0:    pick = want_q[1] ? 3'b010 : want_q[2] ? 3'b100 : want_q[0] ? 3'b001 : 3'b000;
      2'd1:    pick = want_q[2] ? 3'b100 : want_q[0] ? 3'b001 : want_q[1] ? 3'b010 : 3'b000;
      default: pick = want_q[0] ? 3'b001 : want_q[1] ? 3'b010 : want_q[2] ? 3'b100 : 3'b000;
    endcase
    grant = (load && !xv_q) ? pick : 3'b000;
  end

  // Loaded whenever empty (the enable is out_v_q alone); the read's fields as an AND-OR
  // of the one-hot grant.
  logic [22:0] sel_addr;
  logic [1:0]  sel_tag;
  always_comb begin
    sel_addr = '0;
    sel_tag  = '0;
    for (int c = 0; c < int'(NumCh); c++) begin
      sel_addr |= {23{pick[c]}} & {2'(c), h_q[c].off};
      sel_tag  |= {2{pick[c]}} & 2'(c);
    end
  end

  always_comb begin
    rr_d       = (|grant) ? sel_tag : rr_q;
    // Full: until accepted; empty: loaded if anything wants it (not through grant).
    out_v_d    = out_v_q ? !accepted : (xv_q || |want_q);
    out_wr_d   = out_wr_q;
    out_addr_d = out_addr_q;
    out_tag_d  = out_tag_q;
    out_data_d = out_data_q;
    if (!out_v_q) begin
      out_wr_d   = xv_q;
      out_addr_d = xv_q ? {x_q[54:53], x_q[52:32]} : sel_addr;
      out_tag_d  = sel_tag;
      out_data_d = x_q[31:0];
    end
  end

  assign x_take = xq_valid && !xv_q;
  always_ff @(posedge clk_sdram_i) begin
    if (rst_sd) begin
      xv_q       <= 1'b0;
      rr_q       <= 2'd2;
      out_v_q    <= 1'b0;
      out_wr_q   <= 1'b0;
      out_addr_q <= '0;
      out_tag_q  <= 2'd0;
      out_data_q <= 32'd0;
    end else begin
      if (x_take)     xv_q <= 1'b1;
      else if (win_x) xv_q <= 1'b0;
      rr_q       <= rr_d;
      out_v_q    <= out_v_d;
      out_wr_q   <= out_wr_d;
      out_addr_q <= out_addr_d;
      out_tag_q  <= out_tag_d;
      out_data_q <= out_data_d;
    end
    if (x_take) x_q <= xq_data;
  end

  // ---------------------------------------------------------------- controller
  logic        ctl_rd_valid, ctl_rd_last;
  logic [31:0] ctl_rd_data;
  logic [1:0]  ctl_rd_tag;
  /* verilator lint_off UNUSEDSIGNAL */  // refresh strobe: not needed here
  logic        ctl_refresh;
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

  // ---------------------------------------------------------------- info FIFO
  // What each granted read is, in grant order (the controller answers in order): a ring
  // written a clock after the grant, from the granted colour's hold register (out_tag_q
  // selects it; the hold is reloaded a clock later at the soonest), so the arbiter is
  // not in front of the RAM's write port; and a head register, reloaded in the clock after a
  // burst's last word (the next burst's first word comes 2 clocks after it at the
  // soonest; a burst's first word comes 8 clocks after its grant at the soonest). The
  // head's per-word masks are shift registers (vm_q, lm_q) that move on with each word,
  // so bit 0 is the word on the controller's output now: no word index, no multiplexer
  // in front of the return path's flags.
  localparam int unsigned InfoDepth = 8;
  typedef struct packed {
    logic       tbl;
    logic [3:0] vmask;
    logic [3:0] lmask;
    logic [2:0] win;
    logic       comp;
  } info_t;

  info_t       info_mem_q [InfoDepth];
  logic [2:0]  info_wp_q, info_rp_q;
  logic [3:0]  info_cnt_q, info_cnt_d;
  info_t       info_new, info_rd;
  logic        h_tbl_q, h_comp_q;   // the head: what the burst is
  logic [2:0]  h_win_q;
  logic        head_v_q, info_push, info_push_q, head_load;
  logic [3:0]  vm_q, lm_q;          // the head's vmask / lmask, shifted one per word

  always_comb begin
    info_new = '0;
    for (int c = 0; c < int'(NumCh); c++) begin
      if (out_tag_q == 2'(c))
        info_new = '{tbl: h_q[c].tbl, vmask: h_q[c].vmask, lmask: h_q[c].lmask,
                     win: h_q[c].win, comp: h_q[c].comp};
    end
  end
  assign info_push  = |grant;
  assign head_load  = !head_v_q && info_cnt_q != 4'd0;
  assign info_cnt_d = info_cnt_q + 4'(info_push_q) - 4'(head_load);
  // From the registered count only (not this clock's grant): with at most one grant per
  // clock (written a clock later) the ring then holds at most InfoDepth - 1 (in flight
  // are the output register, the controller's request and the bursts coming back).
  assign info_room_d = info_cnt_q <= 4'(InfoDepth - 5);

  assign info_rd = info_mem_q[info_rp_q];
  always_ff @(posedge clk_sdram_i) begin
    if (info_push_q) info_mem_q[info_wp_q] <= info_new;
    // A word never comes in the clock the head is loaded (checked below).
    if (head_load) begin
      h_tbl_q  <= info_rd.tbl;
      h_win_q  <= info_rd.win;
      h_comp_q <= info_rd.comp;
      vm_q     <= info_rd.vmask;
      lm_q     <= info_rd.lmask;
    end else if (ctl_rd_valid) begin
      vm_q <= vm_q >> 1;
      lm_q <= lm_q >> 1;
    end
  end
  always_ff @(posedge clk_sdram_i) begin
    if (rst_sd) begin
      info_push_q <= 1'b0;
      info_wp_q   <= '0;
      info_rp_q   <= '0;
      info_cnt_q  <= '0;
      head_v_q    <= 1'b0;
    end else begin
      info_push_q <= info_push;
      if (info_push_q) info_wp_q <= info_wp_q + 3'd1;
      if (head_load) info_rp_q <= info_rp_q + 3'd1;
      info_cnt_q  <= info_cnt_d;
      if (head_load)                        head_v_q <= 1'b1;
      else if (ctl_rd_valid && ctl_rd_last) head_v_q <= 1'b0;
    end
  end

  // ---------------------------------------------------------------- outstanding reads
  for (genvar c = 0; c < NumCh; c++) begin : g_outst
    req_t rq_head;
    assign rq_head = req_t'(rq_data[c]);
    always_comb begin
      outst_d[c] = outst_q[c] + 3'(grant[c])
                   - 3'(ctl_rd_valid && ctl_rd_last && ctl_rd_tag == 2'(c));
      hv_d[c]    = (hv_q[c] && !grant[c] && !pad_go[c]) || (rq_valid[c] && !hv_q[c]);
      // Next clock's "a read waits in the hold" (the hold's next request, or the kept one).
      want_d[c]  = hv_d[c] && info_room_d && !(hv_q[c] ? h_q[c].pad : rq_head.pad);
    end
    always_ff @(posedge clk_sdram_i) begin
      if (rst_sd) begin
        outst_q[c] <= '0;
        hv_q[c]    <= 1'b0;
        want_q[c]  <= 1'b0;
      end else begin
        outst_q[c] <= outst_d[c];
        want_q[c]  <= want_d[c];
        hv_q[c]    <= hv_d[c];
      end
      if (rq_valid[c] && !hv_q[c]) h_q[c] <= rq_head;
    end
  end

  // ---------------------------------------------------------------- return path
  // Table words go to the entry FIFO, each with its "belongs to the table" flag; block
  // words to the prefetch FIFO, except the burst's words past the line's end
  // (don't-care) and a marker before the line's last word (dropped, counted for the
  // fetcher's credit); a last word that is not a marker is replaced by one. Either
  // fault makes the line malformed (one clock per line): a frame always carries exactly
  // VActive markers, so the display controller's line count never slips. Every push is
  // registered; the fetchers' credit guarantees the room (checked in simulation).
  logic       w_v, w_l, w_mk;
  logic [NumCh-1:0] mal_line_q, malformed, drop_q, mal_q;
  logic [NumCh-1:0][CW-1:0] drop_cnt_q, drop_cnt_d;
  assign w_v  = vm_q[0];
  assign w_l  = lm_q[0];
  assign w_mk = (ctl_rd_data[31:27] == 5'd1);

  for (genvar c = 0; c < NumCh; c++) begin : g_ret
    logic hit, blk, drop;
    assign hit  = ctl_rd_valid && ctl_rd_tag == 2'(c);
    assign blk  = hit && !h_tbl_q && w_v;
    assign drop = blk && !w_l && w_mk;
    assign malformed[c] = blk && w_l && (mal_line_q[c] || !w_mk);
    assign drop_cnt_d[c] = drop_cnt_q[c] + CW'(drop_q[c]);

    always_ff @(posedge clk_sdram_i) begin
      if (rst_sd) begin
        ent_push_q[c]  <= 1'b0;
        pf_push_q[c]   <= 1'b0;
        mal_line_q[c]  <= 1'b0;
        drop_q[c]      <= 1'b0;
        mal_q[c]       <= 1'b0;
        drop_cnt_q[c]  <= '0;
        drop_gray_q[c] <= '0;
      end else begin
        ent_push_q[c] <= hit && h_tbl_q;
        pf_push_q[c]  <= (blk && (w_l || !w_mk)) || pad_go[c];
        if (blk && w_l)  mal_line_q[c] <= 1'b0;
        else if (drop)   mal_line_q[c] <= 1'b1;
        // The count (registered drop, then binary and Gray): one bit per clock.
        drop_q[c]      <= drop;
        mal_q[c]       <= malformed[c];
        drop_cnt_q[c]  <= drop_cnt_d[c];
        drop_gray_q[c] <= drop_cnt_d[c] ^ (drop_cnt_d[c] >> 1);
      end
      ent_wdata_q[c] <= {w_v, ctl_rd_data};
      if (pad_go[c])
        pf_wdata_q[c] <= {h_q[c].comp, h_q[c].win, MarkerWord};
      else
        pf_wdata_q[c] <= {h_comp_q, h_win_q, (w_l && !w_mk) ? MarkerWord : ctl_rd_data};
    end

`ifdef VERILATOR
    always_ff @(posedge clk_sdram_i) begin
      if (!rst_sd && pf_push_q[c] && !pf_wready[c])
        $fatal(1, "de_sdram_frames: colour %0d: prefetch FIFO overflow (credit)", c);
      if (!rst_sd && ent_push_q[c] && !ent_wready[c])
        $fatal(1, "de_sdram_frames: colour %0d: entry FIFO overflow", c);
      if (!rst_sd && ctl_rd_valid && !head_v_q)
        $fatal(1, "de_sdram_frames: read word without its info");
    end
`endif
  end

  // ---------------------------------------------------------------- status across
  // Malformed lines (registered flags): a saturating count in Gray code (it changes by
  // one bit per clock at most: the words come one per 2 clocks, so at most one line ends
  // per clock), read in the pixel domain through two flip-flops.
  logic [7:0] mal_bin_d, mal_bin_q, mal_gray_q;
  (* ASYNC_REG = "TRUE" *) logic [7:0] mal_s1_q, mal_s2_q;
  assign mal_bin_d = (|mal_q && mal_bin_q != 8'hFF) ? mal_bin_q + 8'd1 : mal_bin_q;
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
  end
  function automatic logic [7:0] gray2bin8(logic [7:0] g);
    logic [7:0] b;
    b[7] = g[7];
    for (int i = 6; i >= 0; i--) b[i] = b[i + 1] ^ g[i];
    return b;
  endfunction
  assign malformed_o = gray2bin8(mal_s2_q);

  /* verilator lint_off UNUSEDSIGNAL */  // G/B frame pulses; the FIFOs' ready (credit)
  logic unused;
  assign unused = ^{frame[2:1], ent_wready, pf_wready};
  /* verilator lint_on UNUSEDSIGNAL */
endmodule

`default_nettype wire
