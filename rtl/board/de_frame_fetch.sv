// Frame fetcher of ONE colour, PIXEL clock domain (docs/board.md §4, docs/sdram.md §5,
// docs/sdram-frames-spec.md §1-2): walks a frame's table of lines and asks the SDRAM
// side (de_sdram_frames) for the frame's words, one request per 4-word burst, through a
// dual-clock request FIFO. It runs on the pixel clock because nothing here needs the
// SDRAM clock: a colour needs a burst at most every 4 pixel clocks, and the credit is
// then exact and same-clock (words reserved here minus words the player popped).
//
// Issue side (this module):
//   * at a frame boundary it waits (frame_wait_o) until the sequencer starts the next
//     frame (frame_go_i, with the slot's table offset, window, flag, or no slot: a black
//     frame of VActive empty lines);
//   * table burst: 4 entries from table + 4k, while fewer than VActive are requested and
//     the entry FIFO has room for 4 more beyond every entry reserved (the SDRAM side
//     returns all 4 words of a table burst, each with a flag saying whether it is an
//     entry of the table; the words past the table's end are popped and dropped here);
//   * line: the next entry {len, blk}: len = 0 is an empty line (a padding request: the
//     SDRAM side writes one marker of its own in order, no SDRAM read); else
//     ceil(len / 4) block bursts from blk * 4, each only while the prefetch FIFO has room
//     for the burst's words beyond every word reserved and a margin (credit, below).
//   A request carries what the SDRAM side needs to handle the returning words without
//   arithmetic: table or block or pad, the offset, which of the 4 words belong to the
//   table or line (vmask) and which one is the line's last (lmask), window and flag.
//
// Credit: occ = words reserved (block words that belong to a line, pads) - words the
// player popped - words the SDRAM side dropped (pf_drop_i: early markers of a malformed
// line, counted there and brought across in Gray code; its lag only makes occ larger).
// Every reserved word is either pushed into the prefetch FIFO or dropped, so occ >= the
// FIFO's true fill. A burst needs occ + its words <= PfDepth - PfMargin: the margin
// covers the FIFO write side's own conservative view (the read pointer reaches it a few
// SDRAM clocks late, while the player pops at most one word per pixel clock).
`default_nettype none

module de_frame_fetch #(
  parameter int unsigned PfDepth  = 2048,   // the prefetch FIFO's entries
  parameter int unsigned PfMargin = 8,      // prefetch FIFO words never reserved
  parameter int unsigned EntDepth = 8,      // table entries reserved at most
  localparam int unsigned PW = $clog2(PfDepth),
  localparam int unsigned ReqW = 35
) (
  input  logic            clk_i,
  input  logic            rst_i,
  input  logic [11:0]     vactive_i,       // quasi-static
  // Sequencer: frame boundary.
  output logic            frame_wait_o,    // this colour is at a frame boundary
  input  logic            frame_go_i,      // start the next frame (one clock)
  input  logic            slot_valid_i,    // 0: a black frame
  input  logic [18:0]     table4_i,        // word offset of the frame table / 4
  input  logic [2:0]      window_i,
  input  logic            comp_i,
  // Requests into the dual-clock request FIFO: {tbl, pad, off[20:0], vmask[3:0],
  // lmask[3:0], win[2:0], comp}.
  output logic            req_valid_o,
  input  logic            req_ready_i,
  output logic [ReqW-1:0] req_o,
  // Table words from the dual-clock entry FIFO (show-ahead): {belongs, word[31:0]}.
  input  logic            ent_valid_i,
  output logic            ent_ready_o,
  /* verilator lint_off UNUSEDSIGNAL */  // entry bit 19: blk < 2^19 in a 2^21-word region
  input  logic [32:0]     ent_i,
  /* verilator lint_on UNUSEDSIGNAL */
  // Prefetch FIFO accounting (pixel clock).
  input  logic            pf_pop_i,        // the player took a word
  input  logic [PW+1:0]   pf_drop_i        // words dropped by the SDRAM side (wrapping)
);
  if (PfDepth < 16 || (PfDepth & (PfDepth - 1)) != 0) begin : g_bad_pf
    $fatal(1, "de_frame_fetch: PfDepth must be a power of two >= 16");
  end
  if (PfMargin < 4 || PfMargin + 8 > PfDepth) begin : g_bad_margin   // 2 bursts at least
    $fatal(1, "de_frame_fetch: PfMargin must be >= 4 and leave room for two bursts");
  end
  if (EntDepth < 4 || EntDepth > 64) begin : g_bad_ent
    $fatal(1, "de_frame_fetch: EntDepth must be 4..64");
  end

  localparam int unsigned CW = PW + 2;       // credit counters (wrapping)
  localparam int unsigned EW = $clog2(EntDepth + 1) + 1;

  typedef struct packed {
    logic        tbl;      // table burst: the 4 words go to the entry FIFO
    logic        pad;      // padding marker, no SDRAM read
    logic [20:0] off;      // word offset in the colour's region, a multiple of 4
    logic [3:0]  vmask;    // words of the burst that belong to the table / line
    logic [3:0]  lmask;    // the line's last word (block bursts)
    logic [2:0]  win;
    logic        comp;
  } req_t;

  function automatic logic [3:0] first_n(logic [11:0] left);   // min(left, 4) ones
    if (left >= 12'd4) return 4'b1111;
    return 4'((5'd1 << left[2:0]) - 5'd1);
  endfunction

  // ---------------------------------------------------------------- state
  logic        in_frame_d, in_frame_q, fvalid_d, fvalid_q, fcomp_d, fcomp_q;
  logic [20:0] ftbl_d, ftbl_q;
  logic [2:0]  fwin_d, fwin_q;
  logic [11:0] tbl_req_d, tbl_req_q, tbl_left_d, tbl_left_q, lines_left_d, lines_left_q;
  logic        line_act_d, line_act_q;
  logic [20:0] line_addr_d, line_addr_q;
  logic [11:0] line_left_d, line_left_q;
  logic [CW-1:0] resv_d, resv_q, pops_q;   // words reserved / popped, wrapping
  logic [EW-1:0] ent_resv_d, ent_resv_q;   // table words requested, not yet popped
  logic          rq_v_d, rq_v_q;
  req_t          rq_d, rq_q;

  // ---------------------------------------------------------------- decisions
  logic [CW-1:0] occ;
  logic [2:0]    nval;
  logic          load, room_blk, room_pad, dec_tbl, dec_blk, dec_pad;
  logic          take_ok, ent_ok, ent_len0, ent_pop, take;

  assign occ      = resv_q - pops_q - pf_drop_i;
  assign nval     = (line_left_q >= 12'd4) ? 3'd4 : line_left_q[2:0];
  assign room_blk = (CW + 1)'(occ) + (CW + 1)'(nval) <= (CW + 1)'(PfDepth - PfMargin);
  assign room_pad = (CW + 1)'(occ) + (CW + 1)'(1) <= (CW + 1)'(PfDepth - PfMargin);
  // The request register is free this clock, or its request enters the FIFO now.
  assign load     = !rq_v_q || req_ready_i;
  assign dec_tbl  = in_frame_q && load && fvalid_q && (tbl_left_q != 12'd0) &&
                    (32'(ent_resv_q) + 32'd4 <= 32'(EntDepth));
  assign dec_blk  = in_frame_q && load && !dec_tbl && line_act_q && room_blk;

  // Take the next line: a table entry (words past the table's end are popped and
  // dropped whenever they come), or an empty line of a black frame.
  assign take_ok  = in_frame_q && !line_act_q && (lines_left_q != 12'd0);
  assign ent_ok   = ent_valid_i && ent_i[32];
  assign ent_len0 = (ent_i[31:20] == 12'd0);
  always_comb begin
    dec_pad = 1'b0;
    ent_pop = ent_valid_i && !ent_i[32];
    take    = 1'b0;
    if (take_ok) begin
      if (!fvalid_q || (ent_ok && ent_len0)) begin
        dec_pad = load && !dec_tbl && room_pad;
        take    = dec_pad;
        ent_pop = ent_pop || (dec_pad && fvalid_q);
      end else if (ent_ok) begin
        take    = 1'b1;
        ent_pop = 1'b1;
      end
    end
  end
  assign ent_ready_o = ent_pop;

  always_comb begin
    rq_v_d = rq_v_q && !req_ready_i;
    rq_d   = rq_q;
    if (dec_tbl) begin
      rq_v_d = 1'b1;
      rq_d   = '{tbl: 1'b1, pad: 1'b0, off: ftbl_q + 21'(tbl_req_q),
                 vmask: first_n(tbl_left_q), lmask: 4'b0000, win: fwin_q, comp: fcomp_q};
    end else if (dec_blk) begin
      rq_v_d = 1'b1;
      rq_d   = '{tbl: 1'b0, pad: 1'b0, off: line_addr_q, vmask: first_n(line_left_q),
                 lmask: (line_left_q <= 12'd4) ? 4'(5'd1 << (nval - 3'd1)) : 4'b0000,
                 win: fwin_q, comp: fcomp_q};
    end else if (dec_pad) begin
      rq_v_d = 1'b1;
      rq_d   = '{tbl: 1'b0, pad: 1'b1, off: 21'd0, vmask: 4'b0001, lmask: 4'b0001,
                 win: fwin_q, comp: fcomp_q};
    end
  end

  // ---------------------------------------------------------------- next state
  always_comb begin
    in_frame_d   = in_frame_q;
    fvalid_d     = fvalid_q;
    ftbl_d       = ftbl_q;
    fwin_d       = fwin_q;
    fcomp_d      = fcomp_q;
    tbl_req_d    = tbl_req_q;
    tbl_left_d   = tbl_left_q;
    lines_left_d = lines_left_q;
    line_act_d   = line_act_q;
    line_addr_d  = line_addr_q;
    line_left_d  = line_left_q;

    if (!in_frame_q) begin
      if (frame_go_i) begin
        in_frame_d   = 1'b1;
        fvalid_d     = slot_valid_i;
        ftbl_d       = {table4_i, 2'b00};
        fwin_d       = window_i;
        fcomp_d      = comp_i;
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
        if (!dec_pad) begin
          line_act_d  = 1'b1;
          line_addr_d = {ent_i[18:0], 2'b00};   // blk[19] unused: 2^19 bursts per region
          line_left_d = ent_i[31:20];
        end
      end
      // Done with the frame once every line is taken and its last request is queued.
      if (!line_act_q && lines_left_q == 12'd0 && !rq_v_q) in_frame_d = 1'b0;
    end

    resv_d     = resv_q + (dec_blk ? CW'(nval) : '0) + CW'(dec_pad);
    ent_resv_d = ent_resv_q + (dec_tbl ? EW'(4) : '0) - EW'(ent_pop);
  end

  always_ff @(posedge clk_i) begin
    if (rst_i) begin
      in_frame_q   <= 1'b0;
      fvalid_q     <= 1'b0;
      ftbl_q       <= '0;
      fwin_q       <= 3'd0;
      fcomp_q      <= 1'b0;
      tbl_req_q    <= 12'd0;
      tbl_left_q   <= 12'd0;
      lines_left_q <= 12'd0;
      line_act_q   <= 1'b0;
      line_addr_q  <= '0;
      line_left_q  <= 12'd0;
      resv_q       <= '0;
      pops_q       <= '0;
      ent_resv_q   <= '0;
      rq_v_q       <= 1'b0;
      rq_q         <= '0;
    end else begin
      in_frame_q   <= in_frame_d;
      fvalid_q     <= fvalid_d;
      ftbl_q       <= ftbl_d;
      fwin_q       <= fwin_d;
      fcomp_q      <= fcomp_d;
      tbl_req_q    <= tbl_req_d;
      tbl_left_q   <= tbl_left_d;
      lines_left_q <= lines_left_d;
      line_act_q   <= line_act_d;
      line_addr_q  <= line_addr_d;
      line_left_q  <= line_left_d;
      resv_q       <= resv_d;
      pops_q       <= pops_q + CW'(pf_pop_i);
      ent_resv_q   <= ent_resv_d;
      rq_v_q       <= rq_v_d;
      rq_q         <= rq_d;
    end
  end

  assign frame_wait_o = !in_frame_q;
  assign req_valid_o  = rq_v_q;
  assign req_o        = rq_q;
endmodule

`default_nettype wire
