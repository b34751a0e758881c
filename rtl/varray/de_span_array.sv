// Difference Engine: the span-serial virtual array (docs/fpga.md, "Span-serial array").
//
// The same architectural state as NumCols x-processors (A-D, protect, dis and lock flags
// per column; docs/isa.md section 6), kept in block RAM, and the same pixels for the
// same 48-bit instruction stream, but the work is done only where a command acts. The
// plain array passes every slot through every PE (NumCols operations per slot); here a
// command visits only the columns of its span, one column per clock.
//
//   front end   collects a *group*: an address slot and the data/ACC slots behind it
//               (they act exactly on the address slot's span, isa.md section 5), writes
//               it into a pass table (2**PassAw entries); a group of more than
//               MaxSlots slots is split into passes of MaxSlots (each slot is its own
//               chain, so a split is exact).
//   issue       walks a pass's columns (range: X..X+dX-1, periodic: X, X+dX, ...,
//               clipped at NumCols), one token per clock, reading the column's state.
//   stage 0     Eval0 / Dis of the address slot (after the RAM read and its register).
//   stage 1..K  slot j-1 of the pass: forward differencing with the value carried from
//               the previous column of the same pass (cv_q), or ACC (D += A).
//   write back  the column's state, K+3 clocks after it was read.
//   Refresh     one token: the engine moves to the other of two state banks; once the
//               token reaches write back, the old bank is drained (D[35:24] out, one
//               column per clock, column cleared) while the next line runs.
//
// A token is not issued while its column is in flight (read, not yet written back), so
// passes over overlapping spans see each other's results in stream order. Forward = 1
// narrows that wait to the first K stages: the column's state is bypassed from write
// back (or from the two clocks after it) to the next token's stage 0. Prefetch = 1 decodes
// the next pass a clock ahead and starts it right behind the last token of the running
// one (else a clock later). The levers' cost in clocks per line: docs/performance.md,
// "Span-serial array: levers" (`make bench-span`).
//
// Interface: a valid/ready stream of unskewed slots in, a pixel stream out (NumCols
// pixels per Refresh, in column order, with their column). Acc_mode is global state:
// every column sees Acc_mode and Refresh slots in the same order relative to every other
// command, so one register captured per pass is the per-column flag of the plain array.
// Reset: rst_i for one clock; bank 0 is then cleared through the pipeline and bank 1 by
// the drain (NumCols clocks, busy_o high) before the first pass is issued.
`default_nettype none

module de_span_array
  import de_pkg::*;
#(
  parameter int unsigned NumCols  = 648,  // virtual columns (x-processors)
  parameter int unsigned MaxSlots = 4,    // data/ACC slots per pass (4 = Eval3 in one)
  parameter int unsigned CarryBug = 0,
  parameter int unsigned Forward  = 1,    // bypass write back to a column's next token
  parameter int unsigned Prefetch = 1,    // next pass loaded as the last token issues
  parameter int unsigned PassAw   = 5     // pass table: 2**PassAw entries
) (
  input  logic             clk_i,
  input  logic             rst_i,
  input  logic             instr_valid_i,
  output logic             instr_ready_o,
  input  logic [IdW-1:0]   id_i,
  input  logic [DataW-1:0] data_i,
  output logic             pix_valid_o,
  output logic [PixW-1:0]  pix_o,
  output logic [11:0]      pix_col_o,
  output logic             busy_o         // passes queued or in flight, or clearing
);
  localparam int unsigned K    = MaxSlots;
  localparam int unsigned CW   = 13;                 // column counter: X + dX < 8192
  localparam int unsigned AW   = NumCols > 1 ? $clog2(NumCols) : 1;
  localparam int unsigned PW   = PassAw;             // pass table: 2**PassAw entries
  localparam int unsigned NPass = 1 << PW;
  // Column state: A, B, C, D, pA, pB, pC, dis, lock.
  localparam int unsigned StW  = 4 * DataW + 5;

  if (NumCols < 1 || NumCols > 4096) begin : g_bad_cols
    $fatal(1, "de_span_array: NumCols must be 1..4096, got %0d", NumCols);
  end
  if (MaxSlots < 1 || MaxSlots > 9) begin : g_bad_slots
    $fatal(1, "de_span_array: MaxSlots must be 1..9 (Eval8 = 9), got %0d", MaxSlots);
  end
  if (CarryBug > 1) begin : g_bad_carry_bug
    $fatal(1, "de_span_array: CarryBug must be 0 or 1");
  end
  if (Forward > 1 || Prefetch > 1 || PassAw < 2 || PassAw > 8) begin : g_bad_levers
    $fatal(1, "de_span_array: Forward and Prefetch must be 0 or 1, PassAw 2..8");
  end

  typedef struct packed {
    logic [DataW-1:0] a, b, c, d;
    logic pa, pb, pc, dis, lock;
  } st_t;

  // One slot of a pass: what the identifier's direct bits say, and its value.
  typedef struct packed {
    logic             acc;     // ACC slot (else data slot)
    logic [1:0]       dst, src;
    logic             set, prot;
    logic [DataW-1:0] val;
  } slot_t;

  // A token: one column of one pass on its way through the pipeline.
  typedef struct packed {
    logic          vld;
    logic          nul;        // empty pass: retires, touches no column
    logic          clr;        // reset sweep: clear the column
    logic          rfr;        // Refresh: the bank switch (one token per Refresh)
    logic          bank;       // state bank the token reads and writes
    logic [1:0]    eff;        // address slot's own effect: 0 none, 1 Eval0, 2 Dis
    logic [PixW-1:0] i12;      // Eval0 intensity
    logic          accm;       // Acc_mode in force for the pass's ACC slots
    logic [3:0]    nslot;      // slots of the pass (stages beyond them pass through)
    logic          first;      // first column of the pass: chains start from the slot
    logic          last;       // last token of the pass: it retires the table entry
    logic [PW-1:0] ptr;        // pass table entry
    logic [CW-1:0] col;
  } tok_t;

  localparam logic [1:0] EffNone = 2'd0, EffEval0 = 2'd1, EffDis = 2'd2;

  // Token stages: 0 block RAM read, 1 read data registered (stage 0 logic), s+1 slot
  // stage s, K+2 write back.
  tok_t tok_q [K + 3];

  // The adder with its carry fault as an option (add_word) and the register reads
  // (reg_word, reg_flag) are de_pkg functions, generated from spec/isa.toml and shared
  // with de_pe, the C y-processor model and the Python golden model.
  localparam bit Bug = (CarryBug == 1);

  // ==== front end: slots -> pass table ====================================================
  id_t id;
  assign id = id_t'(id_i);

  // Pass table. The header fields travel in the token (read once, at issue); slot j is
  // read only by stage j+1, so each slot column is its own small memory with one read
  // port (distributed RAM).
  typedef struct packed {
    logic          rfr;
    logic          per;        // periodic addressing
    logic [1:0]    eff;
    logic [11:0]   x, dx;      // range: X, dX. periodic: X (first column), dX (period)
    logic [PixW-1:0] i12;
    logic          accm;
    logic [3:0]    nslot;
    logic [CW-1:0] cend;       // the walk's end, worked out when the pass is written
    logic [CW-1:0] cnx;        // the walk's second column: X + its step
    logic          one;        // the first column is the last (X + step >= cend)
    logic          nul;        // the pass touches no column
  } hdr_t;
  hdr_t  hdr_mem [NPass];
  slot_t slot_q [K];                   // slot j of the pass in stage j+1 (registered)

  logic [PW:0] wr_cnt_d, wr_cnt_q, iss_cnt_d, iss_cnt_q, ret_cnt_d, ret_cnt_q;
  logic [PW-1:0] wr_ptr;
  assign wr_ptr  = wr_cnt_q[PW-1:0];
  // Entry wr_ptr is free while fewer than NPass passes are committed and not retired.
  // Registered, and counted as if the previous clock had committed a pass (one entry
  // is given up): the ready decision then needs no subtraction after the slot's decode.
  logic room_d, room_q;
  assign room_d = (PW + 1)'(wr_cnt_q - ret_cnt_d) < (PW + 1)'(NPass - 1);

  // The open group.
  logic        open_d, open_q, per_d, per_q, accm_d, accm_q;
  logic [1:0]  eff_d, eff_q;
  logic [11:0] x_d, x_q, dx_d, dx_q;
  logic [PixW-1:0] i12_d, i12_q;
  logic [3:0]  nslot_d, nslot_q;

  logic is_dat, closer, full_d, full_q, pend_d, pend_q, commit, take, slot_we, ref_we;
  hdr_t hdr_w;
  logic x_dx_ge_n;
  assign is_dat = !id.addr && !id.refresh && (id.data || id.acc);
  assign closer = !is_dat;
  // Registered from the next state: the ready decision reads them straight from flops.
  assign full_d = (nslot_d == 4'(K));
  // The group holds something to do: slots, or an Eval0 / Dis of its own.
  assign pend_d = open_d && ((nslot_d != '0) || (eff_d != EffNone));
  // A slot that ends the group (or overflows it) waits one clock while the group is
  // written: one table write per clock, in stream order.
  assign commit = instr_valid_i && pend_q && (closer || full_q) && room_q;
  assign take   = instr_valid_i && !(pend_q && (closer || full_q)) &&
                  (room_q || !(id.refresh || (is_dat && open_q)));
  assign slot_we = take && is_dat && open_q;
  assign ref_we  = take && id.refresh;

  always_comb begin
    hdr_w       = '0;
    hdr_w.per   = per_q;
    hdr_w.eff   = eff_q;
    hdr_w.x     = x_q;
    hdr_w.dx    = dx_q;
    hdr_w.i12   = i12_q;
    hdr_w.accm  = accm_q;
    hdr_w.nslot = nslot_q;
    // The end of the walk and the empty pass, from the group's registers: the table read
    // in front of the issue (the prefetch register) then does no arithmetic.
    x_dx_ge_n   = (CW'(x_q) + CW'(dx_q) >= CW'(NumCols));
    hdr_w.cend  = (per_q || x_dx_ge_n) ? CW'(NumCols) : CW'(x_q) + CW'(dx_q);
    hdr_w.nul   = (CW'(x_q) >= hdr_w.cend);
    // The issue keeps "this column is the last" in a register a column ahead; here are
    // its first values. Periodic: step dX (dX = 0: 4096, past any column), end N. Range:
    // step 1, end min(X + dX, N), so X + 1 >= end exactly when dX <= 1 or X >= N - 1;
    // neither form waits for the cend mux above.
    hdr_w.cnx   = CW'(x_q) + (per_q ? ((dx_q == '0) ? CW'(4096) : CW'(dx_q)) : CW'(1));
    hdr_w.one   = per_q ? ((dx_q == '0) || x_dx_ge_n)
                        : ((dx_q <= 12'd1) || (CW'(x_q) >= CW'(NumCols - 1)));
    if (ref_we) begin
      hdr_w       = '0;
      hdr_w.rfr   = 1'b1;
      hdr_w.nul   = 1'b1;
    end
  end

  always_comb begin
    open_d   = open_q;
    per_d    = per_q;
    eff_d    = eff_q;
    x_d      = x_q;
    dx_d     = dx_q;
    i12_d    = i12_q;
    nslot_d  = nslot_q;
    accm_d   = accm_q;
    wr_cnt_d = wr_cnt_q;
    if (commit) begin
      wr_cnt_d = wr_cnt_q + 1'b1;
      // An overflowing group goes on over the same span with its next slots; the address
      // slot's own effect belongs to the first pass only.
      open_d  = !closer;
      nslot_d = '0;
      eff_d   = EffNone;
    end
    if (take) begin
      open_d = 1'b0;
      if (id.addr) begin
        open_d  = 1'b1;
        nslot_d = '0;
        per_d   = (id.sub == SubPeriodic);
        eff_d   = (id.sub == SubEval0) ? EffEval0 : (id.sub == SubDis) ? EffDis : EffNone;
        // Periodic layout: the period in block 0, the first column in block 1 (isa.md 4).
        x_d     = per_d ? word_blk(data_i, 1) : word_blk(data_i, 0);
        dx_d    = per_d ? word_blk(data_i, 0) : word_blk(data_i, 1);
        i12_d   = word_blk(data_i, 2);
      end else if (is_dat) begin
        // Data slots with no address slot in front act nowhere (act = 0 everywhere).
        open_d  = open_q;
        nslot_d = nslot_q + 4'(open_q);
      end else if (id.refresh) begin
        accm_d   = 1'b0;
        wr_cnt_d = wr_cnt_q + 1'b1;
      end else if (id.sub == SubAccmodeOn) begin
        accm_d = 1'b1;
      end else if (id.sub == SubAccmodeOff) begin
        accm_d = 1'b0;
      end
    end
  end
  assign instr_ready_o = take;

  always_ff @(posedge clk_i) begin
    if (commit || ref_we) begin
      hdr_mem[wr_ptr] <= hdr_w;
    end
  end

  // One memory per slot position: one write port (the front end) and one read port,
  // which is what maps onto distributed RAM. It is read for the token one stage ahead
  // and registered, so no RAM read sits in front of a stage's adder.
  // The write is registered first (a clock late): the accept decision in front of it,
  // decoded from the incoming identifier, otherwise ran on into the write enables of all
  // K memories. A slot is read only after its pass is committed (a clock after the slot
  // at the earliest), seen by the issue a clock later and walked after that, so the late
  // write is always in place before the first read.
  logic          sw_we_q;
  logic [3:0]    sw_j_q;
  logic [PW-1:0] sw_ptr_q;
  slot_t         sw_data_q;
  always_ff @(posedge clk_i) begin
    if (rst_i) begin
      sw_we_q <= 1'b0;
    end else begin
      sw_we_q <= slot_we;
    end
  end
  always_ff @(posedge clk_i) begin
    sw_j_q    <= nslot_q;
    sw_ptr_q  <= wr_ptr;
    sw_data_q <= slot_t'({id.acc, id.dst, id.src, id.set, id.prot, data_i});
  end

  for (genvar j = 0; j < K; j++) begin : g_slot_mem
    (* ram_style = "distributed" *) slot_t mem [NPass];
    always_ff @(posedge clk_i) begin
      if (sw_we_q && (sw_j_q == 4'(j))) begin
        mem[sw_ptr_q] <= sw_data_q;
      end
      slot_q[j] <= mem[tok_q[j + 1].ptr];
    end
  end

  // ==== issue: walk the columns of the oldest pass ======================================
  logic          run_d, run_q, scrub_d, scrub_q;
  logic          bank_d, bank_q;      // the bank the engine works on (this line's)
  logic          drain_busy;
  logic [CW-1:0] col_d, col_q, end_d, end_q, step_d, step_q;
  // col + step (the next column) and "col + step >= end" (this column is the pass's
  // last), kept a column ahead: the last-token decision, which decides whether the next
  // pass goes in this clock, then starts at a flip-flop instead of an adder and a
  // compare (the core clock's worst path on the board).
  logic [CW-1:0] cnx_d, cnx_q;
  logic          last_d, last_q;
  tok_t          cur_d, cur_q;        // the running pass's token template
  tok_t          iss;                 // token issued this clock (vld = 0: none)
  logic          hazard;              // the stall test as written (checked against hz_q)
  // The stall test a clock ahead (hz_q): for each column the walk can be at next clock
  // (the same, the next, or the next pass's first), against the tokens that will then be
  // in the first HzStages stages. The walk then reads the test from a flip-flop.
  logic          hz_d, hz_q, hz_stay, hz_adv, hz_new, adv;
  // The next pass, decoded a clock ahead from the pass table (entry ld_cnt): its token
  // template and column range. It goes into the issue registers when the engine is idle,
  // or (Prefetch) in the clock the running pass issues its last token.
  tok_t          nxt_d, nxt_q;
  logic [CW-1:0] ncol_d, ncol_q, nend_d, nend_q, nstep_d, nstep_q, ncnx_d, ncnx_q;
  logic          nlast_d, nlast_q;
  logic          nvld_d, nvld_q, fin, xfer;
  logic [PW:0]   ld_cnt_d, ld_cnt_q;
  // With forwarding a token waits only while an earlier token of its column is in the
  // first K stages: one further on reaches write back (or has passed it) by the time this
  // one needs the column's state, and is bypassed to it (fsel, below).
  localparam int unsigned HzStages = (Forward == 1) ? K : K + 3;

  always_comb begin
    hazard = 1'b0;
    for (int s = 0; s < HzStages; s++) begin
      if (tok_q[s].vld && !tok_q[s].nul && (tok_q[s].col == col_q)) begin
        hazard = 1'b1;
      end
    end
  end

  // Next clock, stage s + 1 holds today's stage s, and stage 0 today's issued token. That
  // token is at col_q, which only the next pass can meet again: a pass's columns rise.
  always_comb begin
    hz_stay = 1'b0;
    hz_adv  = 1'b0;
    hz_new  = iss.vld && !iss.nul && (col_q == ncol_q);
    for (int s = 0; s + 1 < HzStages; s++) begin
      if (tok_q[s].vld && !tok_q[s].nul) begin
        if (tok_q[s].col == col_q) hz_stay = 1'b1;
        if (tok_q[s].col == cnx_q) hz_adv = 1'b1;
        if (tok_q[s].col == ncol_q) hz_new = 1'b1;
      end
    end
    hz_d = xfer ? hz_new : adv ? hz_adv : hz_stay;
  end

  hdr_t hr;
  assign hr = hdr_mem[ld_cnt_q[PW-1:0]];

  // Decode the next pass: its column range and its token template.
  always_comb begin
    nxt_d    = nxt_q;
    ncol_d   = ncol_q;
    nend_d   = nend_q;
    nstep_d  = nstep_q;
    ncnx_d   = ncnx_q;
    nlast_d  = nlast_q;
    nvld_d   = nvld_q && !xfer;
    ld_cnt_d = ld_cnt_q;
    if ((!nvld_q || xfer) && (ld_cnt_q != wr_cnt_q)) begin
      nvld_d      = 1'b1;
      ld_cnt_d    = ld_cnt_q + 1'b1;
      nxt_d       = '0;
      nxt_d.first = 1'b1;
      nxt_d.ptr   = ld_cnt_q[PW-1:0];
      nxt_d.rfr   = hr.rfr;
      nxt_d.eff   = hr.eff;
      nxt_d.i12   = hr.i12;
      nxt_d.accm  = hr.accm;
      nxt_d.nslot = hr.nslot;
      ncnx_d      = hr.cnx;
      nlast_d     = hr.one;
      if (hr.rfr) begin
        ncol_d  = '0;
        nend_d  = '0;
        nstep_d = CW'(1);
        ncnx_d  = CW'(1);
        nlast_d = 1'b1;
      end else if (hr.per) begin
        // Period dX; dX = 0 reloads the countdown with 4095: period 4096 (isa.md 5).
        ncol_d  = CW'(hr.x);
        nend_d  = hr.cend;
        nstep_d = (hr.dx == '0) ? CW'(4096) : CW'(hr.dx);
      end else begin
        ncol_d  = CW'(hr.x);
        nend_d  = hr.cend;
        nstep_d = CW'(1);
      end
      // A pass that touches no column (and the Refresh token) issues one token that
      // only retires the table entry, so passes retire in order.
      nxt_d.nul = hr.nul;
    end
  end

  always_comb begin
    run_d     = run_q;
    scrub_d   = scrub_q;
    bank_d    = bank_q;
    col_d     = col_q;
    end_d     = end_q;
    step_d    = step_q;
    cnx_d     = cnx_q;
    last_d    = last_q;
    cur_d     = cur_q;
    adv       = 1'b0;
    iss_cnt_d = iss_cnt_q;
    iss       = cur_q;
    iss.vld   = 1'b0;
    iss.col   = col_q;
    iss.bank  = bank_q;
    iss.last  = last_q;
    fin       = 1'b0;
    if (scrub_q) begin
      // Reset sweep: clear every column (block RAM has no reset).
      iss.vld = 1'b1;
      iss.clr = 1'b1;
      iss.nul = 1'b0;
      iss.last = 1'b0;
      col_d   = col_q + 1'b1;
      if (col_q == CW'(NumCols - 1)) begin
        scrub_d = 1'b0;
      end
    end else if (run_q && cur_q.rfr) begin
      // Refresh: the engine goes on in the other bank, which the last drain left clear,
      // as soon as that drain is done; this line's bank is drained once every token
      // before this one has written it back (the token reaching write back says so).
      if (!drain_busy) begin
        iss.vld   = 1'b1;
        iss.last  = 1'b1;
        bank_d    = !bank_q;
        run_d     = 1'b0;
        iss_cnt_d = iss_cnt_q + 1'b1;
        fin       = 1'b1;
      end
    end else if (run_q) begin
      if (cur_q.nul || !hz_q) begin
        iss.vld = 1'b1;
        adv     = 1'b1;
        col_d   = cnx_q;
        // cnx_q < end_q <= NumCols here whenever the walk goes on, so the sum below
        // cannot wrap CW bits.
        cnx_d   = cnx_q + step_q;
        last_d  = (cnx_q + step_q >= end_q);
        cur_d.first = 1'b0;
        if (cur_q.nul || iss.last) begin
          iss.last  = 1'b1;
          run_d     = 1'b0;
          iss_cnt_d = iss_cnt_q + 1'b1;
          fin       = 1'b1;
        end
      end
    end
    // Take the next pass into the issue registers.
    xfer = !scrub_q && nvld_q && (!run_q || ((Prefetch == 1) && fin));
    if (xfer) begin
      run_d  = 1'b1;
      cur_d  = nxt_q;
      col_d  = ncol_q;
      end_d  = nend_q;
      step_d = nstep_q;
      cnx_d  = ncnx_q;
      last_d = nlast_q;
    end
  end

  // ==== pipeline ===========================================================================
  // Two banks of column state: the engine works in one while the other, holding the
  // previous line, is drained (pixels out, cleared) by its own ports.
  logic [StW-1:0] ram0 [NumCols];
  logic [StW-1:0] ram1 [NumCols];
  // Block RAM output, registered once more (the DP16KD output register: its clock-to-out
  // without it was the critical path), then the bank mux.
  st_t  rd0_q, rd1_q, rd0_q2, rd1_q2, rd_q, rdf;
  assign rd_q = tok_q[1].bank ? rd1_q2 : rd0_q2;
  st_t  st_q [1:K + 1];                // st_q[s]: state entering stage s
  logic [DataW-1:0] cv_d [1:K], cv_q [1:K];  // per stage: value out of the last column
  st_t  st_s [1:K + 1];                // stage outputs (st_s[s] -> st_q[s])
  logic pixv_d, pixv_q;
  logic [PixW-1:0] pix_d, pix_q;
  logic [11:0] pixc_d, pixc_q;

  // Drain: after a Refresh token has reached write back, read the old bank column by
  // column, send D[35:24] out and write the column back cleared a clock later.
  logic          dpend_d, dpend_q, drun_d, drun_q, dbank_d, dbank_q, dclr_d, dclr_q;
  logic          dwr_d, dwr_q, dwr_q2; // a drain read was issued one / two clocks ago
  logic [AW-1:0] dcol_d, dcol_q, dcol_q2, dcol_q3;
  logic [PixW-1:0] dpix;
  assign dpix       = dbank_q ? rd1_q2.d[DataW-1 -: PixW] : rd0_q2.d[DataW-1 -: PixW];
  assign drain_busy = dpend_q || drun_q || dwr_q || dwr_q2;

  // Forwarding. A token issued d >= K+1 clocks after an earlier one on its column (same
  // bank) enters stage 0 when that one is in write back (d = K+1), or one or two clocks
  // past it (its write not yet in what the block RAM read returned): the column's state
  // then comes from there. Selected a clock ahead, when the token is in tok_q[0], so stage 0
  // sees a registered select; the newest match wins.
  logic          fw1_q, fwb1_q;   // write back a clock ago: valid, bank, column
  logic [AW-1:0] fwc1_q;
  st_t           fws1_q, fws2_q;
  logic [1:0]    fsel_d, fsel_q;
  always_comb begin
    fsel_d = 2'd0;
    if (Forward == 1 && tok_q[0].vld && !tok_q[0].nul) begin
      if (fw1_q && fwb1_q == tok_q[0].bank && fwc1_q == AW'(tok_q[0].col)) begin
        fsel_d = 2'd3;
      end
      if (tok_q[K + 2].vld && !tok_q[K + 2].nul && tok_q[K + 2].bank == tok_q[0].bank &&
          tok_q[K + 2].col == tok_q[0].col) begin
        fsel_d = 2'd2;
      end
      if (tok_q[K + 1].vld && !tok_q[K + 1].nul && tok_q[K + 1].bank == tok_q[0].bank &&
          tok_q[K + 1].col == tok_q[0].col) begin
        fsel_d = 2'd1;
      end
    end
  end
  always_comb begin
    unique case (fsel_q)
      2'd1:    rdf = st_q[K + 1];
      2'd2:    rdf = fws1_q;
      2'd3:    rdf = fws2_q;
      default: rdf = rd_q;
    endcase
  end

  // Stage 0: the address slot's own effect and Refresh.
  always_comb begin
    st_s[1] = rdf;
    if (tok_q[1].vld && !tok_q[1].nul) begin
      if (tok_q[1].clr) begin
        st_s[1] = '0;
      end else if (tok_q[1].eff == EffEval0) begin
        if (!rdf.lock && !rdf.dis) begin
          st_s[1].d    = {tok_q[1].i12, 24'd0};
          st_s[1].lock = 1'b1;
        end
        st_s[1].pa  = 1'b0;
        st_s[1].pb  = 1'b0;
        st_s[1].pc  = 1'b0;
        st_s[1].dis = 1'b0;
      end else if (tok_q[1].eff == EffDis) begin
        st_s[1].dis = 1'b1;
      end
    end
  end

  // Stages 1..K: slot j of the pass (isa.md section 6, architectural form).
  for (genvar s = 1; s <= K; s++) begin : g_stage
    slot_t sl;
    logic  on;
    logic [DataW-1:0] vin, v, sum;
    logic  prot;
    st_t   st;
    assign sl = slot_q[s - 1];
    logic  first, accm;
    assign first = tok_q[s + 1].first;
    assign accm  = tok_q[s + 1].accm;
    assign on    = tok_q[s + 1].vld && !tok_q[s + 1].nul && !tok_q[s + 1].clr &&
                   (tok_q[s + 1].nslot > 4'(s - 1));
    // The first column of a pass gets the slot's own value; inactive columns between
    // active ones pass values unchanged, so every later column gets its left neighbour's.
    assign vin  = first ? sl.val : cv_q[s];
    assign prot = sl.prot && reg_flag(sl.dst, st_q[s].pa, st_q[s].pb, st_q[s].pc);
    assign v    = prot ? reg_word(sl.dst, st_q[s].a, st_q[s].b, st_q[s].c) : vin;
    // One adder per stage: D + A for ACC, the value plus SRC (read before DST is written)
    // for a data slot.
    assign sum  = sl.acc ? add_word(st_q[s].d, st_q[s].a, Bug)
                         : add_word(v, reg_word(sl.src, st_q[s].a, st_q[s].b, st_q[s].c), Bug);

    always_comb begin
      st      = st_q[s];
      cv_d[s] = cv_q[s];
      if (on && !sl.acc) begin
        if (sl.set) begin
          cv_d[s] = vin;
          unique case (sl.dst)
            RegA: begin st.a = vin; st.pa = 1'b1; end
            RegB: begin st.b = vin; st.pb = 1'b1; end
            RegC: begin st.c = vin; st.pc = 1'b1; end
            RegNone: ;
          endcase
        end else begin
          cv_d[s] = sum;
          unique case (sl.dst)
            RegA:    st.a = v;
            RegB:    st.b = v;
            RegC:    st.c = v;
            RegNone: ;
          endcase
        end
      end
      if (on && sl.acc) begin
        // Acc_mode drops a negative A (bit 35) from the sum.
        if (!st_q[s].lock && !st_q[s].dis && !(accm && st_q[s].a[DataW-1])) begin
          st.d = sum;
        end
        st.pa  = 1'b0;
        st.pb  = 1'b0;
        st.pc  = 1'b0;
        st.dis = 1'b0;
      end
      st_s[s + 1] = st;
    end
  end

  // Write back, and retire the pass with its last token.
  logic wb_vld, wb_we, wb_last, wb_bank, wb_rfr;
  logic [AW-1:0] wb_col;
  assign wb_vld  = tok_q[K + 2].vld;
  assign wb_we   = wb_vld && !tok_q[K + 2].nul;
  assign wb_last = tok_q[K + 2].last;
  assign wb_col  = AW'(tok_q[K + 2].col);
  assign wb_bank = tok_q[K + 2].bank;
  assign wb_rfr  = wb_vld && tok_q[K + 2].rfr;

  always_comb begin
    dpend_d = dpend_q;
    drun_d  = drun_q;
    dbank_d = dbank_q;
    dclr_d  = dclr_q;
    dcol_d  = dcol_q;
    dwr_d   = drun_q;
    if (iss.vld && iss.rfr) begin
      dpend_d = 1'b1;
    end
    if (wb_rfr) begin
      dpend_d = 1'b0;
      drun_d  = 1'b1;
      dbank_d = wb_bank;
      dclr_d  = 1'b0;
      dcol_d  = '0;
    end
    if (drun_q) begin
      dcol_d = dcol_q + 1'b1;
      if (dcol_q == AW'(NumCols - 1)) begin
        drun_d = 1'b0;
      end
    end
    pixv_d = dwr_q2 && !dclr_q;
    pix_d  = dpix;
    pixc_d = 12'(dcol_q3);
  end

  // Port use per bank: the engine's tokens (tok bank) and the drain (dbank) never meet
  // in one bank: the engine leaves a bank before the drain starts on it and enters it
  // only after the drain has finished.
  logic re0, re1, we0, we1;
  logic [AW-1:0] ra0, ra1, wa0, wa1;
  logic [StW-1:0] wd0, wd1;
  // The engine reads at its column register every clock, whether or not the token
  // goes out (the data is used only under a valid token): the hazard check stays out
  // of the block RAM's address and enable paths.
  always_comb begin
    re0 = 1'b1;
    re1 = 1'b1;
    ra0 = AW'(col_q);
    ra1 = AW'(col_q);
    we0 = wb_we && !wb_bank;
    we1 = wb_we && wb_bank;
    wa0 = wb_col;
    wa1 = wb_col;
    wd0 = StW'(st_q[K + 1]);
    wd1 = StW'(st_q[K + 1]);
    if (drun_q) begin
      if (!dbank_q) ra0 = dcol_q; else ra1 = dcol_q;
    end
    if (dwr_q) begin
      if (!dbank_q) begin
        we0 = 1'b1; wa0 = dcol_q2; wd0 = '0;
      end else begin
        we1 = 1'b1; wa1 = dcol_q2; wd1 = '0;
      end
    end
  end
  always_comb begin
    ret_cnt_d = ret_cnt_q;
    if (wb_vld && wb_last) begin
      ret_cnt_d = ret_cnt_q + 1'b1;
    end
  end

  always_ff @(posedge clk_i) begin
    if (re0) begin
      rd0_q <= st_t'(ram0[ra0]);
    end
    if (we0) begin
      ram0[wa0] <= wd0;
    end
  end
  always_ff @(posedge clk_i) begin
    if (re1) begin
      rd1_q <= st_t'(ram1[ra1]);
    end
    if (we1) begin
      ram1[wa1] <= wd1;
    end
  end

  // ==== registers ===========================================================================
  always_ff @(posedge clk_i) begin
    if (rst_i) begin
      open_q    <= 1'b0;
      room_q    <= 1'b1;
      full_q    <= 1'b0;
      pend_q    <= 1'b0;
      per_q     <= 1'b0;
      eff_q     <= EffNone;
      x_q       <= '0;
      dx_q      <= '0;
      i12_q     <= '0;
      nslot_q   <= '0;
      accm_q    <= 1'b0;
      wr_cnt_q  <= '0;
      iss_cnt_q <= '0;
      ret_cnt_q <= '0;
      run_q     <= 1'b0;
      scrub_q   <= 1'b1;
      bank_q    <= 1'b0;
      // Reset: the scrub clears bank 0 through the pipeline, the drain clears bank 1.
      dpend_q   <= 1'b0;
      drun_q    <= 1'b1;
      dbank_q   <= 1'b1;
      dclr_q    <= 1'b1;
      dwr_q     <= 1'b0;
      dwr_q2    <= 1'b0;
      dcol_q3   <= '0;
      dcol_q    <= '0;
      dcol_q2   <= '0;
      col_q     <= '0;
      end_q     <= '0;
      step_q    <= '0;
      cnx_q     <= '0;
      last_q    <= 1'b1;
      hz_q      <= 1'b0;
      cur_q     <= '0;
      pixv_q    <= 1'b0;
      pix_q     <= '0;
      pixc_q    <= '0;
      nvld_q    <= 1'b0;
      ld_cnt_q  <= '0;
      nxt_q     <= '0;
      ncol_q    <= '0;
      nend_q    <= '0;
      nstep_q   <= '0;
      ncnx_q    <= '0;
      nlast_q   <= 1'b1;
      fsel_q    <= 2'd0;
      fw1_q     <= 1'b0;
      for (int s = 0; s < K + 3; s++) begin
        tok_q[s] <= '0;
      end
    end else begin
      open_q    <= open_d;
      room_q    <= room_d;
      full_q    <= full_d;
      pend_q    <= pend_d;
      per_q     <= per_d;
      eff_q     <= eff_d;
      x_q       <= x_d;
      dx_q      <= dx_d;
      i12_q     <= i12_d;
      nslot_q   <= nslot_d;
      accm_q    <= accm_d;
      wr_cnt_q  <= wr_cnt_d;
      iss_cnt_q <= iss_cnt_d;
      ret_cnt_q <= ret_cnt_d;
      run_q     <= run_d;
      scrub_q   <= scrub_d;
      bank_q    <= bank_d;
      dpend_q   <= dpend_d;
      drun_q    <= drun_d;
      dbank_q   <= dbank_d;
      dclr_q    <= dclr_d;
      dwr_q     <= dwr_d;
      dwr_q2    <= dwr_q;
      dcol_q3   <= dcol_q2;
      dcol_q    <= dcol_d;
      dcol_q2   <= dcol_q;
      col_q     <= col_d;
      end_q     <= end_d;
      step_q    <= step_d;
      cnx_q     <= cnx_d;
      last_q    <= last_d;
      hz_q      <= hz_d;
      cur_q     <= cur_d;
      pixv_q    <= pixv_d;
      pix_q     <= pix_d;
      pixc_q    <= pixc_d;
      nvld_q    <= nvld_d;
      ld_cnt_q  <= ld_cnt_d;
      nxt_q     <= nxt_d;
      ncol_q    <= ncol_d;
      nend_q    <= nend_d;
      nstep_q   <= nstep_d;
      ncnx_q    <= ncnx_d;
      nlast_q   <= nlast_d;
      fsel_q    <= fsel_d;
      fw1_q     <= wb_we;
      tok_q[0]  <= iss;
      for (int s = 1; s < K + 3; s++) begin
        tok_q[s] <= tok_q[s - 1];
      end
    end
  end

  // Datapath registers: no reset (the reset sweep defines the state before use).
  always_ff @(posedge clk_i) begin
    rd0_q2 <= rd0_q;
    rd1_q2 <= rd1_q;
    fwb1_q <= wb_bank;
    fwc1_q <= wb_col;
    fws1_q <= st_q[K + 1];
    fws2_q <= fws1_q;
    for (int s = 1; s <= K + 1; s++) begin
      st_q[s] <= st_s[s];
    end
    for (int s = 1; s <= K; s++) begin
      cv_q[s] <= cv_d[s];
    end
  end

  assign pix_valid_o   = pixv_q;
  assign pix_o         = pix_q;
  assign pix_col_o     = pixc_q;
  assign busy_o        = scrub_q || run_q || drain_busy || (wr_cnt_q != ret_cnt_q) ||
                         (iss_cnt_q != wr_cnt_q);

`ifdef VERILATOR
  // The walk's look-ahead registers against the sums they stand for (checked in every
  // simulation: a wrong update would otherwise show only as a pass ended early or late).
  always_ff @(posedge clk_i) begin
    if (!rst_i && run_q && !cur_q.rfr &&
        (cnx_q != col_q + step_q || last_q != (col_q + step_q >= end_q)))
      $fatal(1, "de_span_array: walk look-ahead out of step at column %0d", col_q);
    if (!rst_i && run_q && !cur_q.rfr && !cur_q.nul && hz_q != hazard)
      $fatal(1, "de_span_array: stall test a clock ahead (%0d) differs at column %0d",
             hz_q, col_q);
    if (!rst_i && commit && !ref_we && hdr_w.one != (hdr_w.cnx >= hdr_w.cend))
      $fatal(1, "de_span_array: first-column-is-last flag wrong for X %0d", x_q);
  end
`endif

endmodule

`default_nettype wire
