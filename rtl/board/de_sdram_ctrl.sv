// SDR SDRAM controller for the board's frame store (docs/sdram.md §2): the ULX3S's
// 16-bit MT48LC16M16A2 (4 banks x 8192 rows x 512 columns), one clock domain (clk_i is
// the SDRAM clock; the board shell shifts the pin clock's phase).
//
// * Power-up: TinitNs of NOPs, PRECHARGE ALL, 2 x AUTO REFRESH, LOAD MODE REGISTER
//   (burst length 8, sequential, CAS latency CasLatency, single-location writes).
// * Refresh: one AUTO REFRESH every tREFI - RefMargin clocks (precharging the open rows
//   first), so no refresh is ever postponed: the gap between two REFs stays below tREFI
//   even when a request is being finished.
// * Open-row policy, one row per bank: an access to the open row goes straight to READ
//   or WRITE; a miss precharges and activates its bank. Every constraint is a counter
//   per bank (since ACT, since PRECHARGE, since READ, since WRITE) or per device, so a
//   miss in one bank is served under the data burst of another (a row change costs
//   nothing when the PRECHARGE and ACT fit in the 8 clocks of the burst before).
// * Read port: a request is 4 consecutive 32-bit words (one BL8 burst, 8 beats), address
//   aligned to 4 words; the words come back in order on rd_valid_o, one every 2 clocks,
//   CasLatency + 2 clocks after the READ left, with the request's tag. There is no
//   back-pressure: a requester asks only when it has room for 4 words (credit).
//   Requests to open rows run back to back: one READ every 8 clocks, the data bus full.
// * Write port: one 32-bit word, written as two single-location WRITEs (low half at the
//   even column); writes are for the loader, so reads have priority.
//
// Address map (word address, 4-byte words): {bank, row, column[8:1]}; a colour's frame
// store in a bank of its own keeps the three colours' rows open at the same time.
`default_nettype none

module de_sdram_ctrl #(
  parameter int unsigned TckPs      = 8000,     // 125 MHz
  parameter int unsigned CasLatency = 3,
  parameter int unsigned BankBits   = de_sdram_pkg::SdBankBits,   // the pins' widths:
  parameter int unsigned RowBits    = de_sdram_pkg::SdRowBits,    // checked below
  parameter int unsigned ColBits    = 9,
  // Timings of the part, picoseconds (MT48LC16M16A2-6A).
  parameter int unsigned TrcdPs     = 18000,
  parameter int unsigned TrpPs      = 18000,
  parameter int unsigned TrasPs     = 42000,
  parameter int unsigned TrcPs      = 60000,
  parameter int unsigned TrrdPs     = 12000,
  parameter int unsigned TrfcPs     = 60000,
  parameter int unsigned TwrPs      = 12000,
  parameter int unsigned TmrdCk     = 2,
  parameter int unsigned TrefiPs    = 7_812_500,  // 64 ms / 8192 rows
  parameter int unsigned TinitNs    = 100_000,    // power-up wait
  parameter int unsigned RefMargin  = 64,         // clocks of slack before tREFI
  parameter int unsigned TagW       = 2,
  localparam int unsigned AW        = BankBits + RowBits + ColBits - 1,  // word address
  localparam int unsigned PinAW     = RowBits
) (
  input  logic                clk_i,
  input  logic                rst_i,
  // Write port: one 32-bit word.
  input  logic                wr_valid_i,
  output logic                wr_ready_o,
  input  logic [AW-1:0]       wr_addr_i,
  input  logic [31:0]         wr_data_i,
  // Read port: one request = 4 words from rd_req_addr_i (bits [1:0] ignored).
  input  logic                rd_req_valid_i,
  output logic                rd_req_ready_o,
  input  logic [AW-1:0]       rd_req_addr_i,
  input  logic [TagW-1:0]     rd_req_tag_i,
  output logic                rd_valid_o,
  output logic [31:0]         rd_data_o,
  output logic [TagW-1:0]     rd_tag_o,
  output logic                rd_last_o,      // 4th word of a request
  // Status.
  output logic                init_done_o,
  output logic                refresh_o,      // one clock per AUTO REFRESH issued
  // SDRAM pins (registered; de_sdram_pkg).
  output de_sdram_pkg::sdram_out_t sd_o,
  input  logic [de_sdram_pkg::SdDqW-1:0] sd_dq_i
);
  import de_sdram_pkg::*;  // the command codes (sdram_cmd_e)

  // ---------------------------------------------------------------- parameter checks
  if (CasLatency != 2 && CasLatency != 3) begin : g_bad_cl
    $fatal(1, "de_sdram_ctrl: CasLatency must be 2 or 3");
  end
  if (RowBits < ColBits + 2 || RowBits < 11 || ColBits < 8) begin : g_bad_geom
    $fatal(1, "de_sdram_ctrl: RowBits >= ColBits + 2 (A10 and the column share the pins)");
  end
  if (BankBits != de_sdram_pkg::SdBankBits || RowBits != de_sdram_pkg::SdRowBits)
      begin : g_bad_pins
    $fatal(1, "de_sdram_ctrl: BankBits / RowBits must match the pins of de_sdram_pkg");
  end
  if (TckPs < 5000) begin : g_bad_tck
    $fatal(1, "de_sdram_ctrl: TckPs >= 5000");
  end

  // ---------------------------------------------------------------- timings in clocks
  localparam int unsigned NRcd  = (TrcdPs + TckPs - 1) / TckPs;
  localparam int unsigned NRp   = (TrpPs + TckPs - 1) / TckPs;
  localparam int unsigned NRas  = (TrasPs + TckPs - 1) / TckPs;
  localparam int unsigned NRc   = (TrcPs + TckPs - 1) / TckPs;
  localparam int unsigned NRrd  = (TrrdPs + TckPs - 1) / TckPs;
  localparam int unsigned NRfc  = (TrfcPs + TckPs - 1) / TckPs;
  localparam int unsigned NWr   = (TwrPs + TckPs - 1) / TckPs;
  localparam int unsigned NMrd  = TmrdCk;
  localparam int unsigned NBl   = 8;                                   // beats per READ
  localparam int unsigned NRefi = TrefiPs / TckPs - RefMargin;
  localparam int unsigned NInit = (TinitNs * 1000 + TckPs - 1) / TckPs;
  localparam int unsigned NBanks = 1 << BankBits;
  localparam int unsigned PipeL  = CasLatency + NBl;

  if (NRefi < 64 || NRefi > 65535 || NInit > 1048575) begin : g_bad_ref
    $fatal(1, "de_sdram_ctrl: tREFI / tInit out of the counters' range");
  end

  // Gap checks, built for 125 MHz. A command decided now (cmd_d) is on the pins in the
  // next clock; its restart strobe r_* is registered (r_*_q, the clock it is on the
  // pins) and restarts its "since" counter there, so the decision drives only the pins
  // and those strobes. A counter (saturating at 255, "long ago") restarted from r_*_q
  // reads 0 two clocks after the decision, so "at least N clocks between two commands"
  // is since >= N - 2; the flag f_*_q says it for this clock, computed a clock ahead
  // (ge_next with N - 1), and is masked in the clock right after the command (e_*: the
  // counter has not restarted yet), which costs one clock only for 1-clock timings.
  localparam int unsigned SW = 8;
  typedef logic [SW-1:0] since_t;

  if (NRc > 200 || NRfc > 200 || NRas > 200 || NRcd < 1 || NRp < 1 || NWr < 1 ||
      NMrd < 1) begin : g_bad_since
    $fatal(1, "de_sdram_ctrl: a timing is out of the 8-bit counters' range (1..200 clocks)");
  end

  function automatic since_t inc(since_t v);
    return (v == {SW{1'b1}}) ? v : v + 1'b1;
  endfunction

  // Next clock's "gap >= n": restarted now -> since 0 >= n - 1; else inc(v) >= n - 1.
  function automatic logic ge_next(since_t v, logic restart, int unsigned n);
    if (restart) return n <= 1;
    return (n <= 2) || (32'(v) >= n - 2);
  endfunction

  // Mode register: single-location writes (A9), CL, sequential, BL 8.
  localparam logic [PinAW-1:0] ModeWord =
      PinAW'({1'b1, 2'b00, 3'(CasLatency), 1'b0, 3'b011});

  typedef enum logic [2:0] {
    SInitWait, SInitPre, SInitRef, SInitLmr, SRun, SRefPre, SRef
  } state_e;

  typedef struct packed {
    logic            valid;
    logic            odd;
    logic            last;
    logic [TagW-1:0] tag;
  } beat_t;

  // ---------------------------------------------------------------- reset
  // A copy of rst_i in a register of this module's own: the reset's fanout here is this
  // module's flip-flops, not the whole clock domain's net (one clock later).
  logic rst_q;
  always_ff @(posedge clk_i) rst_q <= rst_i;

  // ---------------------------------------------------------------- state
  state_e state_d, state_q;
  logic [19:0] wait_d, wait_q;
  logic        init_ref_d, init_ref_q;     // the first init REF has gone
  logic [15:0] ref_cnt_d, ref_cnt_q;
  logic        ref_due_d, ref_due_q;       // ref_cnt_q >= NRefi

  logic [NBanks-1:0]              open_d, open_q;
  logic [NBanks-1:0][RowBits-1:0] row_d, row_q;
  since_t [NBanks-1:0] s_act_d, s_act_q, s_pre_d, s_pre_q, s_rd_d, s_rd_q, s_wr_d, s_wr_q;
  since_t s_act_any_d, s_act_any_q, s_read_d, s_read_q, s_ref_d, s_ref_q, s_mrs_d, s_mrs_q;
  // Restart strobes of the counters (this clock's command).
  logic [NBanks-1:0] r_act, r_pre, r_rd, r_wr, r_act_q, r_pre_q, r_rd_q, r_wr_q;
  logic              r_act_any, r_read, r_ref, r_mrs, r_refcnt;
  logic              r_act_any_q, r_read_q, r_ref_q, r_mrs_q;
  // Flags as the decision uses them (f masked by a restart on the pins now).
  logic [NBanks-1:0] e_rp, e_ras, e_wr, e_rdb;
  logic              e_rrd, e_rfc, e_mrd, e_bl, e_rdwr;
  // The request's bank's e_* flags, registered (the bank is fixed while it is served),
  // so no bank multiplexer sits in front of the decision.
  logic              c_rcd_d, c_rcd_q, c_rp_d, c_rp_q, c_rc_d, c_rc_q, c_ras_d, c_ras_q;
  logic              c_wr_d, c_wr_q, c_rdb_d, c_rdb_q;
  // Registered gap flags: per bank tRCD, tRP, tRC, tRAS, tWR, own burst out; device tRRD,
  // tRFC, tMRD, READ-to-READ (8 beats), READ-to-WRITE (bus free).
  logic [NBanks-1:0] f_rp_d, f_rp_q, f_ras_d, f_ras_q;
  logic [NBanks-1:0] f_rcd_d, f_rc_d;        // used through c_rcd / c_rc only
  logic [NBanks-1:0] f_wr_d, f_wr_q, f_rdb_d, f_rdb_q;
  logic              f_rrd_d, f_rrd_q, f_rfc_d, f_rfc_q, f_mrd_d, f_mrd_q;
  logic              f_bl_d, f_bl_q, f_rdwr_d, f_rdwr_q;

  // The request being served.
  logic                cur_valid_d, cur_valid_q;
  logic                cur_write_d, cur_write_q;
  logic                cur_beat_d, cur_beat_q;       // write: high half next
  logic [AW-1:0]       cur_addr_d, cur_addr_q;
  logic [31:0]         cur_data_d, cur_data_q;
  logic [TagW-1:0]     cur_tag_d, cur_tag_q;
  // The request's next command, one-hot, set when it is accepted: PRECHARGE (another
  // row is open), ACT (its bank is idle) or READ/WRITE (its row is open).
  logic                st_pre_d, st_pre_q, st_act_d, st_act_q, st_rw_d, st_rw_q;
  logic [TagW-1:0]     iss_tag_d, iss_tag_q;         // tag of the READ on the pins

  // Pins.
  de_sdram_pkg::sdram_cmd_e cmd_d, cmd_q;  // {cs_n, ras_n, cas_n, we_n}
  logic [BankBits-1:0] ba_d, ba_q;
  logic [PinAW-1:0]    a_d, a_q;
  logic [15:0]         dq_d, dq_q;
  logic                dq_oe_d, dq_oe_q;
  logic                cke_q;

  // Read data.
  beat_t [PipeL-1:0]   pipe_d, pipe_q;
  logic [15:0]         low_d, low_q;
  logic                rdv_d, rdv_q, rdl_d, rdl_q;
  logic [31:0]         rdd_d, rdd_q;
  logic [TagW-1:0]     rdt_d, rdt_q;

  // ---------------------------------------------------------------- request decode
  logic [BankBits-1:0]  cur_bank;
  logic [RowBits-1:0]   cur_row;
  logic [ColBits-2:0]   cur_colw;
  logic [BankBits-1:0]  c_bank;            // the bank of the c_* flags (below)
  assign cur_bank = cur_addr_q[AW-1 -: BankBits];
  assign cur_row  = cur_addr_q[ColBits-1 +: RowBits];
  assign cur_colw = cur_addr_q[ColBits-2:0];

  // The request waiting at the ports (reads first). Its open-row compare is made while
  // it waits, and registered: p_hit_q (its bank has its row open), p_idle_q (its bank is
  // idle), p_bank_q, for the port p_rd_q says (1: read), valid when p_ok_q. p_ok_q says
  // that the compare was made in the clock before from the request still waiting now
  // (a request stays on its port, unchanged, until it is taken) and from the bank state
  // still in force (no PRECHARGE or ACT went in that clock). So the request is taken at
  // the soonest in the second clock it waits, and its first step is a flip-flop then.
  logic [BankBits-1:0] new_bank;
  logic [RowBits-1:0]  new_row;
  assign new_bank = rd_req_valid_i ? rd_req_addr_i[AW-1 -: BankBits] : wr_addr_i[AW-1 -: BankBits];
  assign new_row  = rd_req_valid_i ? rd_req_addr_i[ColBits-1 +: RowBits] :
                                     wr_addr_i[ColBits-1 +: RowBits];

  logic                p_ok_d, p_ok_q, p_rd_q, p_hit_q, p_idle_q;
  logic [BankBits-1:0] p_bank_q;
  // The request taken is the one whose compare p_ok_q vouches for, so its port's valid
  // is not in front of the step (a request stays until it is taken; checked in
  // simulation below).
  logic accept, take_rd, take_wr;
  assign accept         = (state_q == SRun) && !cur_valid_q && !ref_due_q && p_ok_q;
  assign rd_req_ready_o = accept && p_rd_q;
  assign wr_ready_o     = accept && !p_rd_q;
  assign take_rd        = accept && p_rd_q;
  assign take_wr        = accept && !p_rd_q;
  assign c_bank         = cur_valid_q ? cur_bank : p_bank_q;

  // ---------------------------------------------------------------- command decision
  // Each command of the request is one AND of its step and its registered gap flags, so
  // the five are exclusive and no priority chain sits in front of the pins.
  logic do_pre, do_act, do_rd, do_wr, do_wr2, all_pre_ok, all_closed_ok;
  // The refresh's PRECHARGE ALL waits for all_pre_ok a clock old: it is computed only
  // in clocks that issue no command (SRun without a request, SRefPre), so it still holds
  // a clock later, and the 4-bank AND is not in front of the pins.
  logic all_pre_ok_q;

  always_comb begin
    e_ras  = f_ras_q & ~r_act_q;
    e_rp   = f_rp_q & ~r_pre_q;
    e_wr   = f_wr_q & ~r_wr_q;
    e_rdb  = f_rdb_q & ~r_rd_q;
    e_rrd  = f_rrd_q & ~r_act_any_q;
    e_bl   = f_bl_q & ~r_read_q;
    e_rdwr = f_rdwr_q & ~r_read_q;
    e_rfc  = f_rfc_q & ~r_ref_q;
    e_mrd  = f_mrd_q & ~r_mrs_q;
    // A PRECHARGE ends the bank's read data CasLatency-1 clocks later: not before the
    // 8 beats of its last READ are out (rdb).
    do_pre = st_pre_q && c_ras_q && c_wr_q && c_rdb_q;
    do_act = st_act_q && c_rp_q && c_rc_q && e_rrd && e_rfc && e_mrd;
    do_rd  = st_rw_q && !cur_write_q && c_rcd_q && e_bl;
    // The write data must not meet read data on DQ: the last READ's beats are on the
    // bus until CasLatency + 7 clocks after it (rdwr).
    do_wr  = st_rw_q && cur_write_q && c_rcd_q && e_rdwr;
    do_wr2 = cur_beat_q;                       // the high half, the clock after do_wr
    all_pre_ok    = &(~open_q | (e_ras & e_wr & e_rdb));
    all_closed_ok = &e_rp;
  end

  always_comb begin
    state_d     = state_q;
    wait_d      = (wait_q != '0) ? wait_q - 1'b1 : wait_q;
    init_ref_d  = init_ref_q;
    r_refcnt    = (state_q == SInitWait || state_q == SInitPre || state_q == SInitRef ||
                   state_q == SInitLmr);
    open_d      = open_q;
    row_d       = row_q;
    r_act       = '0;
    r_pre       = '0;
    r_rd        = '0;
    r_wr        = '0;
    r_act_any   = 1'b0;
    r_read      = 1'b0;
    r_ref       = 1'b0;
    r_mrs       = 1'b0;
    cur_valid_d = cur_valid_q;
    cur_write_d = cur_write_q;
    cur_beat_d  = cur_beat_q;
    cur_addr_d  = cur_addr_q;
    cur_data_d  = cur_data_q;
    cur_tag_d   = cur_tag_q;
    st_pre_d    = st_pre_q;
    st_act_d    = st_act_q;
    st_rw_d     = st_rw_q;
    iss_tag_d   = iss_tag_q;
    cmd_d       = CmdNop;
    ba_d        = ba_q;
    a_d         = a_q;
    dq_d        = dq_q;
    dq_oe_d     = 1'b0;
    refresh_o   = 1'b0;

    unique case (state_q)
      SInitWait: begin
        if (wait_q == '0) state_d = SInitPre;
      end
      SInitPre: begin
        cmd_d   = CmdPre;
        a_d     = '0;
        a_d[10] = 1'b1;                                    // all banks
        r_pre   = '1;
        state_d = SInitRef;
      end
      SInitRef: begin
        if (all_closed_ok && e_rfc) begin
          cmd_d      = CmdRef;
          r_ref      = 1'b1;
          init_ref_d = 1'b1;
          if (init_ref_q) state_d = SInitLmr;
        end
      end
      SInitLmr: begin
        if (e_rfc) begin
          cmd_d   = CmdLmr;
          ba_d    = '0;
          a_d     = ModeWord;
          r_mrs   = 1'b1;
          state_d = SRun;
        end
      end
      SRun: begin
        if (!cur_valid_q) begin
          if (ref_due_q) begin
            state_d = SRefPre;
          end else if (take_rd) begin
            cur_valid_d = 1'b1;
            cur_write_d = 1'b0;
            cur_addr_d  = {rd_req_addr_i[AW-1:2], 2'b00};
            cur_tag_d   = rd_req_tag_i;
          end else if (take_wr) begin
            cur_valid_d = 1'b1;
            cur_write_d = 1'b1;
            cur_beat_d  = 1'b0;
            cur_addr_d  = wr_addr_i;
            cur_data_d  = wr_data_i;
          end
          // The new request's first command, from its compare made a clock ago (p_*_q).
          if (take_rd || take_wr) begin
            st_rw_d  = p_hit_q;
            st_act_d = p_idle_q;
            st_pre_d = !p_hit_q && !p_idle_q;
          end
        end
        // Address and data follow the request's step alone (the pins carry a NOP when
        // no command goes), so only cmd_d and the restarts wait for the gap flags.
        if (cur_valid_q) begin
          ba_d = cur_bank;
          dq_d = cur_beat_q ? cur_data_q[31:16] : cur_data_q[15:0];
          if (st_act_q) begin
            a_d = cur_row;
          end else if (st_pre_q) begin
            a_d = '0;                                      // A10 = 0: this bank only
          end else begin
            a_d = PinAW'({cur_colw, cur_beat_q});
          end
        end
        dq_oe_d = do_wr || do_wr2;
        if (do_wr2) begin
          // Second beat of a write: the high half, one column on.
          cmd_d       = CmdWrite;
          cur_valid_d = 1'b0;
          cur_beat_d  = 1'b0;
        end
        if (do_pre) begin
          cmd_d    = CmdPre;
          st_pre_d = 1'b0;
          st_act_d = 1'b1;
        end
        if (do_act) begin
          cmd_d    = CmdAct;
          st_act_d = 1'b0;
          st_rw_d  = 1'b1;
        end
        if (do_wr) begin
          cmd_d      = CmdWrite;
          st_rw_d    = 1'b0;
          cur_beat_d = 1'b1;
        end
        if (do_rd) begin
          cmd_d       = CmdRead;
          iss_tag_d   = cur_tag_q;
          st_rw_d     = 1'b0;
          cur_valid_d = 1'b0;
        end
        // Bank state and counter restarts follow the command.
        if (do_pre) begin
          open_d[cur_bank] = 1'b0;
          r_pre[cur_bank]  = 1'b1;
        end
        if (do_act) begin
          open_d[cur_bank] = 1'b1;
          row_d[cur_bank]  = cur_row;
          r_act[cur_bank]  = 1'b1;
          r_act_any        = 1'b1;
        end
        if (do_wr || do_wr2) r_wr[cur_bank] = 1'b1;
        if (do_rd) begin
          r_rd[cur_bank] = 1'b1;
          r_read         = 1'b1;
        end
      end
      SRefPre: begin
        if (open_q == '0) begin
          state_d = SRef;
        end else if (all_pre_ok_q) begin
          cmd_d   = CmdPre;
          a_d     = '0;
          a_d[10] = 1'b1;
          r_pre   = open_q;
          open_d  = '0;
          state_d = SRef;
        end
      end
      SRef: begin
        if (all_closed_ok && e_rfc) begin
          cmd_d     = CmdRef;
          r_ref     = 1'b1;
          r_refcnt  = 1'b1;
          refresh_o = 1'b1;
          state_d   = SRun;
        end
      end
      default: state_d = SInitWait;
    endcase
  end

  // ---------------------------------------------------------------- counters and flags
  always_comb begin
    ref_cnt_d   = r_refcnt ? '0 : ((ref_cnt_q == '1) ? ref_cnt_q : ref_cnt_q + 1'b1);
    ref_due_d   = !r_refcnt && (ref_cnt_q >= 16'(NRefi - 1));
    s_act_any_d = r_act_any_q ? '0 : inc(s_act_any_q);
    s_read_d    = r_read_q ? '0 : inc(s_read_q);
    s_ref_d     = r_ref_q ? '0 : inc(s_ref_q);
    s_mrs_d     = r_mrs_q ? '0 : inc(s_mrs_q);
    f_rrd_d     = ge_next(s_act_any_q, r_act_any_q, NRrd - 1);
    f_bl_d      = ge_next(s_read_q, r_read_q, NBl - 1);
    f_rdwr_d    = ge_next(s_read_q, r_read_q, CasLatency + NBl - 1);
    f_rfc_d     = ge_next(s_ref_q, r_ref_q, NRfc - 1);
    f_mrd_d     = ge_next(s_mrs_q, r_mrs_q, NMrd - 1);
    for (int unsigned b = 0; b < NBanks; b++) begin
      s_act_d[b] = r_act_q[b] ? '0 : inc(s_act_q[b]);
      s_pre_d[b] = r_pre_q[b] ? '0 : inc(s_pre_q[b]);
      s_rd_d[b]  = r_rd_q[b] ? '0 : inc(s_rd_q[b]);
      s_wr_d[b]  = r_wr_q[b] ? '0 : inc(s_wr_q[b]);
      f_rcd_d[b] = ge_next(s_act_q[b], r_act_q[b], NRcd - 1);
      f_rc_d[b]  = ge_next(s_act_q[b], r_act_q[b], NRc - 1);
      f_ras_d[b] = ge_next(s_act_q[b], r_act_q[b], NRas - 1);
      f_rp_d[b]  = ge_next(s_pre_q[b], r_pre_q[b], NRp - 1);
      f_wr_d[b]  = ge_next(s_wr_q[b], r_wr_q[b], NWr - 1);
      f_rdb_d[b] = ge_next(s_rd_q[b], r_rd_q[b], NBl - 1);
    end
    // Next clock's e_* of the next clock's request bank: f_*_d masked by this clock's
    // restart strobes (next clock's r_*_q). Only the request's own commands restart its
    // bank's counters in SRun (a new request is accepted in a clock without a command,
    // and the refresh's all-bank PRECHARGE comes with no request; the next request's
    // flags are computed afresh when it is accepted), so the mask is the command itself,
    // not the per-bank strobe selected by the bank: one level less behind the decision.
    // The bank (c_bank) is the request's while one is served (its address does not
    // change then), else the waiting request's (p_bank_q; it matters only if that one is
    // taken now): flip-flops only, not the accept logic.
    c_rcd_d = f_rcd_d[c_bank] && !do_act;
    c_rc_d  = f_rc_d[c_bank] && !do_act;
    c_ras_d = f_ras_d[c_bank] && !do_act;
    c_rp_d  = f_rp_d[c_bank] && !do_pre;
    c_wr_d  = f_wr_d[c_bank] && !(do_wr || do_wr2);
    c_rdb_d = f_rdb_d[c_bank] && !do_rd;
  end

  // The waiting request's compare (registered; see p_ok_q above). The bank state changes
  // only with a PRECHARGE or an ACT (the request's own, or the refresh's PRECHARGE ALL in
  // SRefPre); a compare made in such a clock is not used.
  assign p_ok_d = (rd_req_valid_i || wr_valid_i) && !take_rd && !take_wr &&
                  !do_pre && !do_act && state_q != SRefPre;
  always_ff @(posedge clk_i) begin
    if (rst_q) begin
      p_ok_q   <= 1'b0;
      p_rd_q   <= 1'b0;
      p_hit_q  <= 1'b0;
      p_idle_q <= 1'b0;
      p_bank_q <= '0;
    end else begin
      p_ok_q   <= p_ok_d;
      p_rd_q   <= rd_req_valid_i;
      p_hit_q  <= open_q[new_bank] && (row_q[new_bank] == new_row);
      p_idle_q <= !open_q[new_bank];
      p_bank_q <= new_bank;
    end
  end

`ifdef VERILATOR
  // The ports' contract: a request waits on its port, unchanged, until it is taken.
  logic [AW-1:0] p_addr_q;
  always_ff @(posedge clk_i) begin
    p_addr_q <= rd_req_valid_i ? rd_req_addr_i : wr_addr_i;
    if (!rst_q && p_ok_q && (p_rd_q ? !rd_req_valid_i : !wr_valid_i))
      $fatal(1, "de_sdram_ctrl: a waiting %s request was withdrawn",
             p_rd_q ? "read" : "write");
    if (!rst_q && p_ok_q && (p_rd_q ? rd_req_addr_i : wr_addr_i) != p_addr_q)
      $fatal(1, "de_sdram_ctrl: a waiting request's address changed");
  end
`endif

  // ---------------------------------------------------------------- read data
  always_comb begin
    pipe_d = '0;
    for (int unsigned j = 0; j + 1 < PipeL; j++) pipe_d[j] = pipe_q[j + 1];
    if (cmd_q == CmdRead) begin
      // Beat i is on DQ at the SDRAM's edge READ + CasLatency + i; the READ is on the
      // pins now (the SDRAM takes it at the next edge), so beat i is captured
      // CasLatency + i clocks after that edge: pipe position CasLatency - 1 + i after it.
      for (int unsigned i = 0; i < NBl; i++) begin
        pipe_d[CasLatency - 1 + i].valid = 1'b1;
        pipe_d[CasLatency - 1 + i].odd   = i[0];
        pipe_d[CasLatency - 1 + i].last  = (i == NBl - 1);
        pipe_d[CasLatency - 1 + i].tag   = iss_tag_q;
      end
    end
    low_d = low_q;
    rdv_d = 1'b0;
    rdl_d = 1'b0;
    rdd_d = rdd_q;
    rdt_d = rdt_q;
    if (pipe_q[0].valid) begin
      if (!pipe_q[0].odd) begin
        low_d = sd_dq_i;
      end else begin
        rdv_d = 1'b1;
        rdl_d = pipe_q[0].last;
        rdd_d = {sd_dq_i, low_q};
        rdt_d = pipe_q[0].tag;
      end
    end
  end

  // ---------------------------------------------------------------- registers
  always_ff @(posedge clk_i) begin
    if (rst_q) all_pre_ok_q <= 1'b0;
    else       all_pre_ok_q <= all_pre_ok &&
                               ((state_q == SRun && !cur_valid_q) || state_q == SRefPre);
  end

  always_ff @(posedge clk_i) begin
    if (rst_q) begin
      state_q     <= SInitWait;
      wait_q      <= 20'(NInit);
      init_ref_q  <= 1'b0;
      ref_cnt_q   <= '0;
      ref_due_q   <= 1'b0;
      open_q      <= '0;
      row_q       <= '0;
      s_act_q     <= '1;
      s_pre_q     <= '1;
      s_rd_q      <= '1;
      s_wr_q      <= '1;
      s_act_any_q <= '1;
      s_read_q    <= '1;
      s_ref_q     <= '1;
      s_mrs_q     <= '1;
      f_rp_q      <= '1;
      f_ras_q     <= '1;
      f_wr_q      <= '1;
      f_rdb_q     <= '1;
      f_rrd_q     <= 1'b1;
      f_rfc_q     <= 1'b1;
      f_mrd_q     <= 1'b1;
      f_bl_q      <= 1'b1;
      f_rdwr_q    <= 1'b1;
      r_act_q     <= '0;
      r_pre_q     <= '0;
      r_rd_q      <= '0;
      r_wr_q      <= '0;
      r_act_any_q <= 1'b0;
      r_read_q    <= 1'b0;
      r_ref_q     <= 1'b0;
      r_mrs_q     <= 1'b0;
      c_rcd_q     <= 1'b1;
      c_rc_q      <= 1'b1;
      c_ras_q     <= 1'b1;
      c_rp_q      <= 1'b1;
      c_wr_q      <= 1'b1;
      c_rdb_q     <= 1'b1;
      cur_valid_q <= 1'b0;
      cur_write_q <= 1'b0;
      cur_beat_q  <= 1'b0;
      cur_addr_q  <= '0;
      cur_data_q  <= '0;
      cur_tag_q   <= '0;
      st_pre_q    <= 1'b0;
      st_act_q    <= 1'b0;
      st_rw_q     <= 1'b0;
      iss_tag_q   <= '0;
      cmd_q       <= CmdNop;
      ba_q        <= '0;
      a_q         <= '0;
      dq_q        <= '0;
      dq_oe_q     <= 1'b0;
      cke_q       <= 1'b1;
      pipe_q      <= '0;
      low_q       <= '0;
      rdv_q       <= 1'b0;
      rdl_q       <= 1'b0;
      rdd_q       <= '0;
      rdt_q       <= '0;
    end else begin
      state_q     <= state_d;
      wait_q      <= wait_d;
      init_ref_q  <= init_ref_d;
      ref_cnt_q   <= ref_cnt_d;
      ref_due_q   <= ref_due_d;
      open_q      <= open_d;
      row_q       <= row_d;
      s_act_q     <= s_act_d;
      s_pre_q     <= s_pre_d;
      s_rd_q      <= s_rd_d;
      s_wr_q      <= s_wr_d;
      s_act_any_q <= s_act_any_d;
      s_read_q    <= s_read_d;
      s_ref_q     <= s_ref_d;
      s_mrs_q     <= s_mrs_d;
      f_rp_q      <= f_rp_d;
      f_ras_q     <= f_ras_d;
      f_wr_q      <= f_wr_d;
      f_rdb_q     <= f_rdb_d;
      f_rrd_q     <= f_rrd_d;
      f_rfc_q     <= f_rfc_d;
      f_mrd_q     <= f_mrd_d;
      f_bl_q      <= f_bl_d;
      f_rdwr_q    <= f_rdwr_d;
      r_act_q     <= r_act;
      r_pre_q     <= r_pre;
      r_rd_q      <= r_rd;
      r_wr_q      <= r_wr;
      r_act_any_q <= r_act_any;
      r_read_q    <= r_read;
      r_ref_q     <= r_ref;
      r_mrs_q     <= r_mrs;
      c_rcd_q     <= c_rcd_d;
      c_rc_q      <= c_rc_d;
      c_ras_q     <= c_ras_d;
      c_rp_q      <= c_rp_d;
      c_wr_q      <= c_wr_d;
      c_rdb_q     <= c_rdb_d;
      cur_valid_q <= cur_valid_d;
      cur_write_q <= cur_write_d;
      cur_beat_q  <= cur_beat_d;
      cur_addr_q  <= cur_addr_d;
      cur_data_q  <= cur_data_d;
      cur_tag_q   <= cur_tag_d;
      st_pre_q    <= st_pre_d;
      st_act_q    <= st_act_d;
      st_rw_q     <= st_rw_d;
      iss_tag_q   <= iss_tag_d;
      cmd_q       <= cmd_d;
      ba_q        <= ba_d;
      a_q         <= a_d;
      dq_q        <= dq_d;
      dq_oe_q     <= dq_oe_d;
      cke_q       <= 1'b1;
      pipe_q      <= pipe_d;
      low_q       <= low_d;
      rdv_q       <= rdv_d;
      rdl_q       <= rdl_d;
      rdd_q       <= rdd_d;
      rdt_q       <= rdt_d;
    end
  end

  assign sd_o.cke   = cke_q;
  assign sd_o.cs_n  = cmd_q[3];
  assign sd_o.ras_n = cmd_q[2];
  assign sd_o.cas_n = cmd_q[1];
  assign sd_o.we_n  = cmd_q[0];
  assign sd_o.ba    = ba_q;
  assign sd_o.a     = a_q;
  assign sd_o.dqm   = '0;
  assign sd_o.dq    = dq_q;
  assign sd_o.dq_oe = dq_oe_q;
  assign rd_valid_o  = rdv_q;
  assign rd_data_o   = rdd_q;
  assign rd_tag_o    = rdt_q;
  assign rd_last_o   = rdl_q;
  assign init_done_o = (state_q == SRun) || (state_q == SRefPre) || (state_q == SRef);

  // A read request is 4 aligned words: the address's two low bits are not used.
  logic unused_rd_lo;
  assign unused_rd_lo = ^rd_req_addr_i[1:0];

endmodule

`default_nettype wire
