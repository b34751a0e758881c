// Frame fetcher of ONE colour, SDRAM clock domain (docs/board.md §4,
// docs/sdram-frames-spec.md §1-2): walks a frame's table of lines in SDRAM and writes
// the frame's words, exactly one end-of-line marker per line, into the colour's prefetch
// FIFO (de_async_fifo, to the pixel clock), each word with the frame's window and
// compensation flag ({comp, window[2:0], word[31:0]}).
//
// Issue side:
//   * at a frame boundary it waits (frame_wait_o) until the sequencer starts the next
//     frame (frame_go_i, with the slot's table offset, window, flag, or no slot: a black
//     frame of VActive empty lines);
//   * table burst: 4 entries from table + 4k, while fewer than VActive are requested and
//     the entry FIFO has room for them and every entry in flight;
//   * line: the next entry {len, blk}: len = 0 is an empty line (a padding marker of our
//     own, no SDRAM read); else ceil(len / 4) block bursts from blk * 4, each only while
//     the prefetch FIFO has room for 4 more words beyond every word reserved (credit:
//     wfree_i is conservative, the reservations are exact), so it never overflows.
//   A burst is decided a clock ahead into the request register (req_*_o come from
//   flip-flops, so the arbiter's choice is the only logic between here and the
//   controller's input register); its words and entries are reserved when it is decided,
//   its info entry is written when it is granted. A new request is decided only when the
//   register is empty (one idle clock per burst of this colour, while the controller
//   takes a burst every 8 clocks at most). The issue side is done with a frame when it
//   has taken VActive lines and its last request is granted.
// Return side: the controller answers requests in order (rd_valid_i: this colour's tag);
// an info FIFO remembers what each request (and each padding marker, to keep it in order)
// is. Table words go to the entry FIFO; block words to the prefetch FIFO, except the
// burst's words past the line's end (don't-care) and a marker before the line's last
// word (dropped); a last word that is not a marker is replaced by one. Either fault
// makes the line malformed (malformed_o, one clock per line): a frame always carries
// exactly VActive markers, so the display controller's line count never slips.
`default_nettype none

module de_frame_fetch #(
  parameter int unsigned PfDepth   = 2048,   // the prefetch FIFO's entries
  parameter int unsigned InfoDepth = 8,      // requests (and pads) in flight
  parameter int unsigned EntDepth  = 8,      // table entries buffered
  localparam int unsigned PW = $clog2(PfDepth)
) (
  input  logic          clk_i,
  input  logic          rst_i,
  input  logic [11:0]   vactive_i,       // quasi-static
  // Sequencer: frame boundary.
  output logic          frame_wait_o,    // this colour is at a frame boundary
  input  logic          frame_go_i,      // start the next frame (one clock)
  input  logic          slot_valid_i,    // 0: a black frame
  input  logic [18:0]   table4_i,        // word offset of the frame table / 4
  input  logic [2:0]    window_i,
  input  logic          comp_i,
  // Read requests (to the arbiter): 4 words from req_off_o (a multiple of 4).
  output logic          req_valid_o,
  output logic [20:0]   req_off_o,
  input  logic          req_grant_i,
  // Read data of this colour, in request order.
  input  logic          rd_valid_i,
  input  logic [31:0]   rd_data_i,
  // Prefetch FIFO write side.
  output logic          pf_push_o,
  output logic [35:0]   pf_data_o,
  input  logic [PW:0]   pf_free_i,
  // Status.
  output logic          malformed_o
);
  if (PfDepth < 16 || (PfDepth & (PfDepth - 1)) != 0) begin : g_bad_pf
    $fatal(1, "de_frame_fetch: PfDepth must be a power of two >= 16");
  end
  if (InfoDepth < 4 || (InfoDepth & (InfoDepth - 1)) != 0) begin : g_bad_info
    $fatal(1, "de_frame_fetch: InfoDepth must be a power of two >= 4");
  end
  if (EntDepth < 8 || (EntDepth & (EntDepth - 1)) != 0) begin : g_bad_ent
    $fatal(1, "de_frame_fetch: EntDepth must be a power of two >= 8");
  end

  localparam logic [31:0] MarkerWord = 32'h0800_0000;   // LUT code 1 = REFRESH
  localparam int unsigned IW = $clog2(InfoDepth);
  localparam int unsigned EW = $clog2(EntDepth);

  typedef enum logic [1:0] {KPad, KTable, KBlock} kind_e;
  typedef struct packed {
    kind_e      kind;
    logic [2:0] nval;     // words of the burst that belong to the table / line (1..4)
    logic       last;     // the line's last burst
    logic [2:0] win;
    logic       comp;
  } info_t;

  function automatic logic is_marker(logic [4:0] code);   // the word's LUT code
    return code == 5'd1;
  endfunction

  // ---------------------------------------------------------------- state
  logic        in_frame_d, in_frame_q, fvalid_d, fvalid_q, fcomp_d, fcomp_q;
  logic [20:0] ftbl_d, ftbl_q;
  logic [2:0]  fwin_d, fwin_q;
  logic [11:0] tbl_req_d, tbl_req_q;
  // Down-counters, so the decisions test a zero instead of comparing with VActive.
  logic [11:0] tbl_left_d, tbl_left_q, lines_left_d, lines_left_q;
  // Credit flags, registered with a margin (below).
  logic        credit4_d, credit4_q, credit1_d, credit1_q;
  logic [EW:0] ent_space_d, ent_space_q;   // entry FIFO room minus entries in flight
  logic        line_act_d, line_act_q;
  logic [20:0] line_addr_d, line_addr_q;
  logic [11:0] line_left_d, line_left_q;
  logic [PW+1:0] resv_d, resv_q;          // prefetch-FIFO words reserved, not yet pushed
  logic [EW:0]   ent_resv_d, ent_resv_q;  // table entries requested, not yet returned
  logic          mal_line_d, mal_line_q;
  logic [1:0]    widx_d, widx_q;
  // The request register: a burst decided, waiting for its grant.
  logic          rq_v_d, rq_v_q;
  logic [20:0]   rq_off_d, rq_off_q;
  info_t         rq_info_d, rq_info_q;

  info_t         info_q [InfoDepth];
  logic [IW-1:0] info_wp_q, info_rp_q;
  logic [IW:0]   info_cnt_q;
  logic [31:0]   ent_q [EntDepth];
  logic [EW-1:0] ent_wp_q, ent_rp_q;
  logic [EW:0]   ent_cnt_q;

  // ---------------------------------------------------------------- issue side
  logic        info_room, credit4, credit1, dec_tbl, dec_blk, grant;
  logic        take_ok, take, take_pad, ent_pop, pad_ok;
  /* verilator lint_off UNUSEDSIGNAL */
  logic [31:0] ent_head;      // bit 19 unused (below)
  /* verilator lint_on UNUSEDSIGNAL */
  logic        info_push;
  info_t       info_new;

  // An entry is {len[11:0], blk[19:0]}; blk < 2^19 in a 2^21-word region, so blk[19]
  // is not used (the block address wraps in the region).
  assign ent_head  = ent_q[ent_rp_q];
  // Room for the decided request and the one in the register when it is granted.
  assign info_room = info_cnt_q <= (IW + 1)'(InfoDepth - 2);
  // Credit, registered: computed from this clock's reservations and free count with a
  // margin of 4, it still holds a clock later, because meanwhile the free count falls
  // only by words that were reserved, and at most one burst (4 words) or one pad is
  // reserved per clock.
  assign credit4   = credit4_q;
  assign credit1   = credit1_q;
  // One more word of margin: a word leaves the reservations a clock before it reaches
  // the FIFO (the registered push below), so the free count may not show it yet.
  assign credit4_d = (resv_q + (PW + 2)'(9)) <= (PW + 2)'(pf_free_i);
  assign credit1_d = (resv_q + (PW + 2)'(6)) <= (PW + 2)'(pf_free_i);
  // Decide a burst into the empty request register: the table first.
  assign dec_tbl   = in_frame_q && !rq_v_q && fvalid_q && (tbl_left_q != 12'd0) &&
                     info_room && (ent_space_q >= (EW + 1)'(4));
  assign dec_blk   = in_frame_q && !rq_v_q && !dec_tbl && line_act_q && info_room && credit4;
  assign grant     = req_grant_i && rq_v_q;
  assign req_valid_o = rq_v_q;
  assign req_off_o   = rq_off_q;

  // Take the next line (an entry, or an empty line of a black frame). A padding marker
  // waits until nothing is in flight or waiting (then no grant can push the info FIFO in
  // the same clock): it is at the head of the info FIFO at once and leaves in the next
  // clock, before any later request's data can arrive, so a pad never holds up a read
  // word (which has no back-pressure); one pad per 2 clocks.
  assign pad_ok   = (info_cnt_q == '0) && !rq_v_q && credit1;
  assign take_ok  = in_frame_q && !line_act_q && (lines_left_q != 12'd0);
  always_comb begin
    take     = 1'b0;
    take_pad = 1'b0;
    ent_pop  = 1'b0;
    if (take_ok) begin
      if (!fvalid_q) begin
        take_pad = pad_ok;
      end else if (ent_cnt_q != '0) begin
        if (ent_head[31:20] == 12'd0) begin
          take_pad = pad_ok;
          ent_pop  = take_pad;
        end else begin
          ent_pop  = 1'b1;
        end
      end
      take = take_pad || ent_pop;
    end
  end

  always_comb begin
    rq_v_d    = rq_v_q && !grant;
    rq_off_d  = rq_off_q;
    rq_info_d = rq_info_q;
    if (dec_tbl) begin
      rq_v_d    = 1'b1;
      rq_off_d  = ftbl_q + 21'(tbl_req_q);
      rq_info_d = '{kind: KTable, nval: (tbl_left_q >= 12'd4) ? 3'd4 : 3'(tbl_left_q),
                    last: 1'b0, win: fwin_q, comp: fcomp_q};
    end else if (dec_blk) begin
      rq_v_d    = 1'b1;
      rq_off_d  = line_addr_q;
      rq_info_d = '{kind: KBlock, nval: (line_left_q >= 12'd4) ? 3'd4 : 3'(line_left_q),
                    last: (line_left_q <= 12'd4), win: fwin_q, comp: fcomp_q};
    end
    info_push = grant || take_pad;
    info_new  = grant ? rq_info_q :
                '{kind: KPad, nval: 3'd1, last: 1'b1, win: fwin_q, comp: fcomp_q};
  end

  // ---------------------------------------------------------------- return side
  info_t  head;
  logic   has_head, pad_now, word_in, in_val, last_word, info_pop, ent_push, pf_push;
  logic [31:0] pf_word;
  logic   resv_dec, ent_resv_dec, malformed;

  assign head     = info_q[info_rp_q];
  assign has_head = info_cnt_q != '0;
  // A padding marker is alone in the info FIFO (pad_ok): no read word of this colour
  // can arrive while it is at the head.
  assign pad_now  = has_head && head.kind == KPad;
  assign word_in  = rd_valid_i && has_head && head.kind != KPad;
  assign in_val   = {1'b0, widx_q} < head.nval;
  assign last_word = head.last && ({1'b0, widx_q} == head.nval - 3'd1);

  always_comb begin
    pf_push      = 1'b0;
    pf_word      = rd_data_i;
    ent_push     = 1'b0;
    resv_dec     = 1'b0;
    ent_resv_dec = 1'b0;
    malformed    = 1'b0;
    mal_line_d   = mal_line_q;
    widx_d       = widx_q;
    info_pop     = 1'b0;
    if (pad_now) begin
      pf_push  = 1'b1;
      pf_word  = MarkerWord;
      resv_dec = 1'b1;
      info_pop = 1'b1;
    end else if (word_in) begin
      widx_d   = widx_q + 2'd1;
      info_pop = (widx_q == 2'd3);
      if (head.kind == KTable) begin
        ent_resv_dec = 1'b1;
        ent_push     = in_val;
      end else begin
        resv_dec = 1'b1;
        if (in_val) begin
          if (last_word) begin
            pf_push    = 1'b1;
            pf_word    = is_marker(rd_data_i[31:27]) ? rd_data_i : MarkerWord;
            malformed  = mal_line_q || !is_marker(rd_data_i[31:27]);
            mal_line_d = 1'b0;
          end else if (is_marker(rd_data_i[31:27])) begin
            mal_line_d = 1'b1;            // an early marker: dropped
          end else begin
            pf_push = 1'b1;
          end
        end
      end
    end
  end

  // ---------------------------------------------------------------- next state
  always_comb begin
    in_frame_d  = in_frame_q;
    fvalid_d    = fvalid_q;
    ftbl_d      = ftbl_q;
    fwin_d      = fwin_q;
    fcomp_d     = fcomp_q;
    tbl_req_d    = tbl_req_q;
    tbl_left_d   = tbl_left_q;
    lines_left_d = lines_left_q;
    line_act_d  = line_act_q;
    line_addr_d = line_addr_q;
    line_left_d = line_left_q;

    if (!in_frame_q) begin
      if (frame_go_i) begin
        in_frame_d = 1'b1;
        fvalid_d   = slot_valid_i;
        ftbl_d     = {table4_i, 2'b00};
        fwin_d     = window_i;
        fcomp_d    = comp_i;
        tbl_req_d    = 12'd0;
        tbl_left_d   = vactive_i;
        lines_left_d = vactive_i;
        line_act_d   = 1'b0;
      end
    end else begin
      if (dec_tbl) begin
        tbl_req_d  = tbl_req_q + 12'd4;
        tbl_left_d = (tbl_left_q >= 12'd4) ? tbl_left_q - 12'd4 : 12'd0;
      end
      if (dec_blk) begin
        line_addr_d = line_addr_q + 21'd4;
        line_left_d = (line_left_q >= 12'd4) ? line_left_q - 12'd4 : 12'd0;
        line_act_d  = (line_left_q > 12'd4);
      end
      if (take) begin
        lines_left_d = lines_left_q - 12'd1;
        if (fvalid_q && !take_pad) begin
          line_act_d  = 1'b1;
          line_addr_d = {ent_head[18:0], 2'b00};
          line_left_d = ent_head[31:20];
        end
      end
      if (!line_act_q && lines_left_q == 12'd0 && !rq_v_q) in_frame_d = 1'b0;
    end

    resv_d = resv_q + (dec_blk ? (PW + 2)'(4) : '0) + (PW + 2)'(take_pad)
             - (PW + 2)'(resv_dec);
    ent_resv_d = ent_resv_q + (dec_tbl ? (EW + 1)'(4) : '0) - (EW + 1)'(ent_resv_dec);
    // Room in the entry FIFO beyond the entries in flight: a table burst takes 4, a
    // popped entry gives 1 back, a returned word past the table's end gives its 1 back.
    ent_space_d = ent_space_q - (dec_tbl ? (EW + 1)'(4) : '0) + (EW + 1)'(ent_pop)
                  + (EW + 1)'(ent_resv_dec && !ent_push);
  end

  always_ff @(posedge clk_i) begin
    if (info_push) info_q[info_wp_q] <= info_new;
    if (ent_push)  ent_q[ent_wp_q]   <= rd_data_i;
  end

  always_ff @(posedge clk_i) begin
    if (rst_i) begin
      in_frame_q  <= 1'b0;
      fvalid_q    <= 1'b0;
      ftbl_q      <= '0;
      fwin_q      <= 3'd0;
      fcomp_q     <= 1'b0;
      tbl_req_q   <= 12'd0;
      tbl_left_q  <= 12'd0;
      lines_left_q <= 12'd0;
      credit4_q   <= 1'b0;
      credit1_q   <= 1'b0;
      ent_space_q <= (EW + 1)'(EntDepth);
      line_act_q  <= 1'b0;
      line_addr_q <= '0;
      line_left_q <= 12'd0;
      resv_q      <= '0;
      ent_resv_q  <= '0;
      mal_line_q  <= 1'b0;
      widx_q      <= 2'd0;
      rq_v_q      <= 1'b0;
      rq_off_q    <= '0;
      rq_info_q   <= '{kind: KPad, nval: 3'd1, last: 1'b0, win: 3'd0, comp: 1'b0};
      info_wp_q   <= '0;
      info_rp_q   <= '0;
      info_cnt_q  <= '0;
      ent_wp_q    <= '0;
      ent_rp_q    <= '0;
      ent_cnt_q   <= '0;
    end else begin
      in_frame_q  <= in_frame_d;
      fvalid_q    <= fvalid_d;
      ftbl_q      <= ftbl_d;
      fwin_q      <= fwin_d;
      fcomp_q     <= fcomp_d;
      tbl_req_q   <= tbl_req_d;
      tbl_left_q  <= tbl_left_d;
      lines_left_q <= lines_left_d;
      credit4_q   <= credit4_d;
      credit1_q   <= credit1_d;
      ent_space_q <= ent_space_d;
      line_act_q  <= line_act_d;
      line_addr_q <= line_addr_d;
      line_left_q <= line_left_d;
      resv_q      <= resv_d;
      ent_resv_q  <= ent_resv_d;
      mal_line_q  <= mal_line_d;
      widx_q      <= widx_d;
      rq_v_q      <= rq_v_d;
      rq_off_q    <= rq_off_d;
      rq_info_q   <= rq_info_d;
      if (info_push) info_wp_q <= info_wp_q + 1'b1;
      if (info_pop)  info_rp_q <= info_rp_q + 1'b1;
      info_cnt_q  <= info_cnt_q + (IW + 1)'(info_push) - (IW + 1)'(info_pop);
      if (ent_push)  ent_wp_q <= ent_wp_q + 1'b1;
      if (ent_pop)   ent_rp_q <= ent_rp_q + 1'b1;
      ent_cnt_q   <= ent_cnt_q + (EW + 1)'(ent_push) - (EW + 1)'(ent_pop);
    end
  end

  assign frame_wait_o = !in_frame_q;
  // The push to the prefetch FIFO is registered (the info FIFO's read, the marker test
  // and the FIFO's pointer arithmetic are then in different clocks).
  logic        pf_push_q;
  logic [35:0] pf_data_q;
  always_ff @(posedge clk_i) begin
    if (rst_i) pf_push_q <= 1'b0;
    else       pf_push_q <= pf_push;
    pf_data_q <= {head.comp, head.win, pf_word};
  end
  assign pf_push_o    = pf_push_q;
  assign pf_data_o    = pf_data_q;
  assign malformed_o  = malformed;
endmodule

`default_nettype wire
