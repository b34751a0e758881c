// Behavioural, timing-checking model of a 16-bit SDR SDRAM: the ULX3S v3.0.x part
// (docs/sdram.md §1). SIMULATION ONLY (Verilator 5 via cocotb, or inside a Verilated
// board top); it is not synthesisable and not written in the RTL style of rtl/: one
// clocked process calls tasks, as a vendor model does.
//
// Part: Micron MT48LC16M16A2TG-6A (emard/ulx3s v3.0.3 BOM, U2), 256 Mbit = 32 MB,
// 4 banks x 8192 rows x 512 columns x 16 bits; the defaults below are its -6A timings
// (Micron 256Mb SDR data sheet, table "AC operating conditions"). The parameters in
// picoseconds are turned into clock cycles (rounded up) from TckPs, so one model
// serves any controller clock; the 64 MB AS4C32M16SB of other ULX3S boards is
// ColBits 10 with its own timings.
//
// Pins: cs_n/ras_n/cas_n/we_n, ba, a, dqm, cke sampled at the rising edge. DQ is three
// ports, dq_i (controller drives), dq_o and dq_oe_o (model drives): Verilator has no
// resolved inout nets across the cocotb boundary and the FPGA's I/O buffer splits
// them the same way (a TRELLIS_IO or BB cell with I/O/T), so the board shell joins
// them at the pin. rst_i is not a pin: it stands for power-on (contents, mode and
// counters cleared), so that several cocotb tests can share one simulation.
//
// Read data: the word of a READ registered at edge n is on dq_o from just after edge
// n+CL-1, to be sampled by the controller at edge n+CL (the data sheet's tAC/tOH
// window collapsed onto the edge). DQM masks write data in the same cycle (latency 0)
// and read data two cycles later (latency 2: dq_oe_o low).
//
// Checks (each one counts in err_count_o, sets its bit in err_seen_o, is the code in
// err_code_o and prints "sdram_sdr16: cycle N: <NAME>: <what>", also into LogFile or
// the file named by +sdram_log=<path>):
//   INIT      command during the power-up wait; ACT/REF/LMR before PRECHARGE ALL;
//             ACT before the 2 init REFs and the LMR
//   TRCD      READ/WRITE sooner than tRCD after ACT of that bank
//   TRP       ACT/REF/LMR sooner than tRP after the bank's (auto-)precharge began
//   TRAS      PRECHARGE (or an auto-precharge's start) sooner than tRAS after ACT
//   TRAS_MAX  a row open longer than tRAS(max)
//   TRC       ACT sooner than tRC after the previous ACT of the same bank
//   TRRD      ACT sooner than tRRD after an ACT of another bank
//   TRFC      any command but NOP sooner than tRFC after AUTO REFRESH
//   TMRD      any command but NOP sooner than tMRD after LOAD MODE REGISTER
//   TWR       PRECHARGE sooner than tWR after the bank's last written data
//   BANK      READ/WRITE to an idle (or auto-precharging) bank, ACT to an active bank,
//             REF/LMR with a bank open
//   MODE      READ/WRITE before LOAD MODE REGISTER; reserved CL/BL codes; interleaved
//             bursts; CL 2 faster than tCK(2); full-page burst with auto-precharge;
//             LMR while a burst is in flight
//   REFRESH   more than (RefPostpone+1) x tREFI between AUTO REFRESHes once refresh
//             has started (tREFI = tREF / RefRows); see below
//   DQ        bus contention: WRITE data while the model drives read data
//   CKE       CKE low (power-down, self refresh, clock suspend: not modelled)
//
// Refresh interval: the data sheet asks for RefRows AUTO REFRESH commands per tREF
// (8192 per 64 ms), evenly spaced or in bursts. The model checks the gap between two
// consecutive REFs against (RefPostpone + 1) x tREFI: a controller may postpone up to
// RefPostpone refreshes (8, as JEDEC allows for DDR; the SDR data sheet does not
// count them) and must then catch up. It is checked every cycle, so a controller
// that stops refreshing is flagged when the gap is exceeded, not at its next REF.
//
// Simplifications (documented, conservative): an auto-precharge burst is taken to run
// to its end (an interrupted one starts its precharge later in the model than in the
// part, which can only flag a legal ACT, never pass an illegal one); an
// auto-precharge that would start before tRAS is a TRAS violation (no tRAS lockout
// assumed); unwritten locations read as UninitWord.
//
// Preload (simulation back door, docs/sdram-frames-spec.md §5): PreloadFile, or the file
// named by +sdram_image=<path>, holds text lines "<addr> <word>" in hex, '#' starting a
// comment: addr is the controller's word address {bank, row, column[ColBits-1:1]}, word
// 32 bits, stored as two 16-bit columns, [15:0] at the even column and [31:16] at the odd
// one. It is read once; every power-on (initial, rst_i) starts from that image instead
// of an empty memory. A malformed line is a $fatal naming the file and line.
`default_nettype none
// A behavioural model: blocking assignments inside the clocked process are its sequential
// program (outputs to the controller go out through <= at the end, so there is no race),
// and its cycle arithmetic mixes int and longint on purpose (all values small, positive).
/* verilator lint_off BLKSEQ */
/* verilator lint_off WIDTH */

module sdram_sdr16 #(
  parameter int unsigned      TckPs       = 8000,           // controller clock period
  // Geometry (MT48LC16M16A2: 4 x 8192 x 512 x 16).
  parameter int unsigned      BankBits    = 2,
  parameter int unsigned      RowBits     = 13,
  parameter int unsigned      ColBits     = 9,
  // Timings, picoseconds (-6A speed grade).
  parameter int unsigned      TrcdPs      = 18000,
  parameter int unsigned      TrpPs       = 18000,
  parameter int unsigned      TrasPs      = 42000,
  parameter int unsigned      TrasMaxPs   = 120_000_000,
  parameter int unsigned      TrcPs       = 60000,
  parameter int unsigned      TrrdPs      = 12000,
  parameter int unsigned      TrfcPs      = 60000,
  parameter int unsigned      TwrPs       = 12000,
  parameter int unsigned      TmrdCk      = 2,              // clocks
  parameter int unsigned      TckCl2MinPs = 10000,          // fastest clock for CL 2
  parameter int unsigned      TrefNs      = 64_000_000,     // 64 ms
  parameter int unsigned      RefRows     = 8192,
  parameter int unsigned      RefPostpone = 8,
  parameter int unsigned      TinitNs     = 100_000,        // 100 us power-up wait
  parameter logic [15:0]      UninitWord  = 16'h0000,
  parameter string            LogFile     = "",             // "" = stdout only
  parameter string            PreloadFile = "",             // "" = +sdram_image= or none
  parameter bit               Verbose     = 1'b1,           // print each violation
  localparam int unsigned     AddrBits    = (RowBits > ColBits + 2) ? RowBits : ColBits + 2
) (
  input  wire logic                clk_i,
  input  wire logic                rst_i,       // power-on (not a pin of the part)
  input  wire logic                cke_i,
  input  wire logic                cs_n_i,
  input  wire logic                ras_n_i,
  input  wire logic                cas_n_i,
  input  wire logic                we_n_i,
  input  wire logic [BankBits-1:0] ba_i,
  input  wire logic [AddrBits-1:0] a_i,
  input  wire logic [1:0]          dqm_i,
  input  wire logic [15:0]         dq_i,
  output      logic [15:0]         dq_o,
  output      logic                dq_oe_o,
  // Checker outputs.
  output      logic [31:0]         err_count_o,
  output      logic [15:0]         err_seen_o,  // bit e: a violation of code e was seen
  output      logic [3:0]          err_code_o,  // code of the last violation
  output      logic [31:0]         cycle_o,     // edges since power-on
  output      logic                init_done_o, // PRECHARGE ALL, 2 REF, LMR done
  output      logic [31:0]         ref_count_o, // AUTO REFRESH commands since power-on
  output      logic [2:0]          cl_o,        // programmed CAS latency (0 = none)
  output      logic [9:0]          bl_o         // programmed burst length (0 = none)
);
  // Elaboration checks.
  if (BankBits < 1 || BankBits > 3) begin : g_bad_bank
    $fatal(1, "sdram_sdr16: BankBits must be 1..3");
  end
  if (ColBits < 8 || ColBits > 12 || RowBits < 11 || RowBits > 14) begin : g_bad_geom
    $fatal(1, "sdram_sdr16: ColBits 8..12, RowBits 11..14");
  end
  if (TckPs < 1000) begin : g_bad_tck
    $fatal(1, "sdram_sdr16: TckPs must be >= 1000");
  end

  // Error codes (err_code_o, err_seen_o bit).
  localparam int unsigned EInit = 1, ETrcd = 2, ETrp = 3, ETras = 4, ETrasMax = 5,
                          ETrc = 6, ETrrd = 7, ETrfc = 8, ETmrd = 9, ETwr = 10,
                          EBank = 11, EMode = 12, ERefresh = 13, EDq = 14, ECke = 15;

  // Timings in clocks: ceil(ps / TckPs).
  localparam int unsigned NRcd    = (TrcdPs + TckPs - 1) / TckPs;
  localparam int unsigned NRp     = (TrpPs + TckPs - 1) / TckPs;
  localparam int unsigned NRas    = (TrasPs + TckPs - 1) / TckPs;
  localparam int unsigned NRasMax = TrasMaxPs / TckPs;                // floor: the limit
  localparam int unsigned NRc     = (TrcPs + TckPs - 1) / TckPs;
  localparam int unsigned NRrd    = (TrrdPs + TckPs - 1) / TckPs;
  localparam int unsigned NRfc    = (TrfcPs + TckPs - 1) / TckPs;
  localparam int unsigned NWr     = (TwrPs + TckPs - 1) / TckPs;
  localparam int unsigned NMrd    = TmrdCk;
  localparam longint unsigned NRefi   = longint'(TrefNs) * 1000 / RefRows / TckPs;  // floor
  localparam longint unsigned NRefMax = NRefi * (RefPostpone + 1);
  localparam longint unsigned NInit   = (longint'(TinitNs) * 1000 + TckPs - 1) / TckPs;
  localparam int unsigned NBanks  = 1 << BankBits;
  localparam int unsigned NCols   = 1 << ColBits;
  localparam longint      Never   = -(64'sd1 << 40);  // "long ago" for last-event times

  // --------------------------------------------------------------------------------
  // State.
  logic [15:0] mem [int unsigned];      // sparse: {bank, row, col} -> word
  logic [15:0] pre [int unsigned];      // the preload image, the contents at power-on
  bit          mem_is_pre;              // mem equals pre (no write since power-on)
  int          last_act_bank;

  longint    cyc;                        // index of the current edge
  int        log_fd;
  // Per bank.
  bit        active  [NBanks];
  int        row     [NBanks];
  longint    t_act   [NBanks];           // last ACT
  longint    t_pre   [NBanks];           // (auto-)precharge began (may be in the future)
  longint    t_wdata [NBanks];           // last data word written
  bit        ap_wr   [NBanks];           // write burst with auto-precharge in progress
  // Device.
  longint    t_act_any, t_ref, t_mrs;
  bit        mode_set, pre_all_done, ref_flagged;
  int        init_refs;
  int        cl, bl;                     // bl 0 = full page
  logic [15:0] dq_drv;                   // what dq_o / dq_oe_o carry after this edge
  bit          oe_drv;
  bit        wb_single;                  // A9: single-location writes
  // Write burst (data registered with the command and the following edges).
  bit        wr_on;
  int        wr_bank, wr_row, wr_col, wr_idx, wr_len;
  // Read bursts: tokens that reach the output register at a given edge.
  localparam int unsigned NTok = 8;
  bit        tk_on    [NTok];
  longint    tk_at    [NTok];
  bit        tk_stop  [NTok];            // a terminate: ends the burst of bank tk_bank
  bit        tk_any   [NTok];            // ... of any bank (BURST TERMINATE)
  int        tk_bank  [NTok], tk_row [NTok], tk_col [NTok], tk_len [NTok];
  bit        rd_on;
  bit        lmr_now;                    // a LOAD MODE REGISTER at this edge
  int        rd_bank, rd_row, rd_col, rd_idx, rd_len;
  logic [1:0] dqm_q1;                    // DQM of the previous edge (read latency 2)

  int unsigned err_count;
  logic [15:0] err_seen;
  logic [3:0]  err_code;
  int          ref_count;

  function automatic string code_name(int c);
    case (c)
      EInit:    return "INIT";
      ETrcd:    return "TRCD";
      ETrp:     return "TRP";
      ETras:    return "TRAS";
      ETrasMax: return "TRAS_MAX";
      ETrc:     return "TRC";
      ETrrd:    return "TRRD";
      ETrfc:    return "TRFC";
      ETmrd:    return "TMRD";
      ETwr:     return "TWR";
      EBank:    return "BANK";
      EMode:    return "MODE";
      ERefresh: return "REFRESH";
      EDq:      return "DQ";
      ECke:     return "CKE";
      default:  return "?";
    endcase
  endfunction

  task automatic violation(input int c, input string what);
    string msg;
    err_count  = err_count + 1;
    err_seen[c] = 1'b1;
    err_code   = 4'(c);
    msg = $sformatf("sdram_sdr16: cycle %0d: %s: %s", cyc, code_name(c), what);
    if (Verbose) $display("%s", msg);
    if (log_fd != 0) begin
      $fdisplay(log_fd, "%s", msg);
      $fflush(log_fd);
    end
  endtask

  // A minimum spacing: `what` happened `gap` clocks after the event, needs `need`.
  task automatic need_gap(input int c, input longint since, input int need,
                          input string what);
    longint gap;
    gap = cyc - since;
    if (gap < longint'(need)) begin
      violation(c, $sformatf("%s %0d clocks after, needs %0d", what, gap, need));
    end
  endtask

  typedef int unsigned uint_t;
  function automatic uint_t key(int b, int r, int col);
    return (uint_t'(b) << (RowBits + ColBits)) | (uint_t'(r) << ColBits) | uint_t'(col);
  endfunction

  // Column of beat i of a burst from `start` (sequential; wraps inside the burst's
  // aligned block, or the whole row for a full page).
  function automatic int burst_col(int start, int i, int len);
    if (len >= NCols) return (start + i) % NCols;
    return (start & ~(len - 1)) | ((start + i) & (len - 1));
  endfunction

  task automatic power_on();
    // A reset held for many clocks must not copy a large image every clock.
    if (!mem_is_pre) mem = pre;
    mem_is_pre = 1'b1;
    cyc = -1;
    for (int b = 0; b < NBanks; b++) begin
      active[b]  = 1'b0;
      row[b]     = 0;
      t_act[b]   = Never;
      t_pre[b]   = Never;
      t_wdata[b] = Never;
      ap_wr[b]   = 1'b0;
    end
    t_act_any    = Never;
    last_act_bank = -1;
    t_ref        = Never;
    t_mrs        = Never;
    mode_set     = 1'b0;
    pre_all_done = 1'b0;
    ref_flagged  = 1'b0;
    init_refs    = 0;
    cl           = 0;
    bl           = 1;
    wb_single    = 1'b0;
    wr_on        = 1'b0;
    rd_on        = 1'b0;
    for (int k = 0; k < NTok; k++) tk_on[k] = 1'b0;
    dqm_q1       = 2'b00;
    err_count    = 0;
    err_seen     = '0;
    err_code     = '0;
    ref_count    = 0;
    dq_drv       = '0;
    oe_drv       = 1'b0;
  endtask

  task automatic add_token(input longint at, input bit stop, input bit any, input int b,
                           input int r, input int col, input int len);
    for (int k = 0; k < NTok; k++) begin
      if (!tk_on[k]) begin
        tk_on[k]   = 1'b1;
        tk_at[k]   = at;
        tk_stop[k] = stop;
        tk_any[k]  = any;
        tk_bank[k] = b;
        tk_row[k]  = r;
        tk_col[k]  = col;
        tk_len[k]  = len;
        return;
      end
    end
    $fatal(1, "sdram_sdr16: read token overflow (model bug)");
  endtask

  // The write burst of bank b ends now: an auto-precharge starts tWR after its last data.
  task automatic end_write();
    if (wr_on && ap_wr[wr_bank]) begin
      t_pre[wr_bank] = t_wdata[wr_bank] + NWr;
      ap_wr[wr_bank] = 1'b0;
    end
    wr_on = 1'b0;
  endtask

  // A bank leaves ACTIVE by PRECHARGE now (checks tRAS, tWR, tRAS max).
  task automatic precharge_bank(input int b);
    // Precharging an idle bank is a NOP, except that the power-up PRECHARGE ALL starts
    // tRP for the first REF / LMR.
    if (!active[b]) begin
      if (!pre_all_done && !ap_wr[b]) t_pre[b] = cyc;
      return;
    end
    need_gap(ETras, t_act[b], NRas, $sformatf("PRECHARGE of bank %0d: ACT", b));
    need_gap(ETwr, t_wdata[b], NWr, $sformatf("PRECHARGE of bank %0d: last write data", b));
    active[b] = 1'b0;
    t_pre[b]  = cyc;
    if (wr_on && wr_bank == b) begin   // a PRECHARGE ends the bank's write burst
      ap_wr[b] = 1'b0;
      wr_on    = 1'b0;
    end
    // ... and its read burst, CL-1 clocks later (last word sampled at edge cyc+CL-1).
    if (cl > 0) add_token(cyc + cl - 1, 1'b1, 1'b0, b, 0, 0, 0);
  endtask

  function automatic bit all_idle();
    for (int b = 0; b < NBanks; b++) if (active[b] || ap_wr[b]) return 1'b0;
    return 1'b1;
  endfunction

  task automatic check_all_precharged(input string what);
    for (int b = 0; b < NBanks; b++) begin
      need_gap(ETrp, t_pre[b], NRp, $sformatf("%s: precharge of bank %0d", what, b));
    end
  endtask

  task automatic check_common(input string what);
    need_gap(ETrfc, t_ref, NRfc, $sformatf("%s: AUTO REFRESH", what));
    need_gap(ETmrd, t_mrs, NMrd, $sformatf("%s: LOAD MODE REGISTER", what));
  endtask

  // --------------------------------------------------------------------------------
  // Commands.
  task automatic cmd_active(input int b, input int r);
    check_common("ACT");
    if (!(pre_all_done && init_refs >= 2 && mode_set)) begin
      violation(EInit, "ACT before PRECHARGE ALL, 2 x AUTO REFRESH and LOAD MODE REGISTER");
    end
    if (active[b]) begin
      violation(EBank, $sformatf("ACT to bank %0d, which is active (row %0d)", b, row[b]));
    end
    need_gap(ETrp, t_pre[b], NRp, $sformatf("ACT of bank %0d: its precharge", b));
    need_gap(ETrc, t_act[b], NRc, $sformatf("ACT of bank %0d: its previous ACT", b));
    if (last_act_bank != b) begin
      need_gap(ETrrd, t_act_any, NRrd, $sformatf("ACT of bank %0d: ACT of another bank", b));
    end
    active[b] = 1'b1;
    row[b]    = r;
    t_act[b]  = cyc;
    t_act_any = cyc;
    last_act_bank = b;
  endtask

  task automatic cmd_rw(input bit is_write, input int b, input int col, input bit ap);
    string nm;
    int    len;
    nm = is_write ? "WRITE" : "READ";
    check_common(nm);
    if (!mode_set) begin
      violation(EMode, $sformatf("%s before LOAD MODE REGISTER (no CAS latency, burst)", nm));
      return;
    end
    if (!active[b]) begin
      violation(EBank, $sformatf("%s to bank %0d, which is idle%s", nm, b,
                                 ap_wr[b] ? " (auto-precharging)" : ""));
      return;
    end
    need_gap(ETrcd, t_act[b], NRcd, $sformatf("%s to bank %0d: its ACT", nm, b));
    len = (bl == 0) ? NCols : bl;
    if (is_write && wb_single) len = 1;
    if (ap && bl == 0) begin
      violation(EMode, $sformatf("%s with auto-precharge in full-page burst mode", nm));
    end
    // Any READ/WRITE ends the write burst in progress (its data stops at this edge).
    end_write();
    if (is_write) begin
      // The model must not be driving read data into the cycle of this edge.
      if (oe_drv) begin
        violation(EDq, "WRITE data while read data is on DQ (mask it with DQM 2 clocks before)");
      end
      // A WRITE ends every read burst now.
      rd_on = 1'b0;
      for (int k = 0; k < NTok; k++) tk_on[k] = 1'b0;
      oe_drv  = 1'b0;
      wr_on   = 1'b1;
      wr_bank = b;
      wr_row  = row[b];
      wr_col  = col;
      wr_idx  = 0;
      wr_len  = len;
      if (ap) begin
        ap_wr[b]  = 1'b1;
        active[b] = 1'b0;
        t_pre[b]  = longint'(cyc) + (64'sd1 << 40);   // not yet: set when the burst ends
        if (cyc + len - 1 + NWr - t_act[b] < NRas) begin
          violation(ETras, $sformatf("WRITE with auto-precharge of bank %0d: precharge %0d clocks after ACT, needs %0d",
                                     b, cyc + len - 1 + NWr - t_act[b], NRas));
        end
      end
    end else begin
      add_token(cyc + cl - 1, 1'b0, 1'b0, b, row[b], col, len);
      if (ap) begin
        active[b] = 1'b0;
        // Precharge begins when the last word has left the array (BL clocks on).
        t_pre[b] = cyc + len;
        if (t_pre[b] - t_act[b] < NRas) begin
          violation(ETras, $sformatf("READ with auto-precharge of bank %0d: precharge %0d clocks after ACT, needs %0d",
                                     b, t_pre[b] - t_act[b], NRas));
        end
      end
    end
  endtask

  task automatic cmd_precharge(input bit all, input int b);
    check_common("PRECHARGE");
    if (all) begin
      for (int k = 0; k < NBanks; k++) precharge_bank(k);
      if (cyc >= longint'(NInit)) pre_all_done = 1'b1;
    end else begin
      precharge_bank(b);
    end
  endtask

  task automatic cmd_refresh();
    check_common("AUTO REFRESH");
    if (!pre_all_done) violation(EInit, "AUTO REFRESH before the initial PRECHARGE ALL");
    if (!all_idle()) violation(EBank, "AUTO REFRESH with a bank open");
    check_all_precharged("AUTO REFRESH");
    t_ref     = cyc;
    ref_flagged = 1'b0;
    ref_count = ref_count + 1;
    if (init_refs < 2) init_refs = init_refs + 1;
  endtask

  task automatic cmd_lmr(input logic [AddrBits-1:0] op);
    int c;
    check_common("LOAD MODE REGISTER");
    if (!pre_all_done) violation(EInit, "LOAD MODE REGISTER before the initial PRECHARGE ALL");
    if (!all_idle()) violation(EBank, "LOAD MODE REGISTER with a bank open");
    check_all_precharged("LOAD MODE REGISTER");
    // Read data still to come is checked at the end of the edge (lmr_now), once the
    // bursts that end at this edge have ended; write data at this edge is a conflict.
    if (wr_on) violation(EMode, "LOAD MODE REGISTER during a write burst");
    lmr_now = 1'b1;
    c = int'(op[6:4]);
    if (c != 2 && c != 3) begin
      violation(EMode, $sformatf("CAS latency code %0d reserved (2 and 3 only)", c));
      c = 3;
    end
    if (c == 2 && TckPs < TckCl2MinPs) begin
      violation(EMode, $sformatf("CAS latency 2 needs tCK >= %0d ps, clock is %0d ps",
                                 TckCl2MinPs, TckPs));
    end
    case (op[2:0])
      3'd0: bl = 1;
      3'd1: bl = 2;
      3'd2: bl = 4;
      3'd3: bl = 8;
      3'd7: bl = 0;
      default: begin
        violation(EMode, $sformatf("burst length code %0d reserved", op[2:0]));
        bl = 1;
      end
    endcase
    if (op[3]) violation(EMode, "interleaved burst type (not modelled; use sequential)");
    if (op[8:7] != 2'b00) violation(EMode, "operating mode A8:A7 must be 00");
    if (op[AddrBits-1:10] != '0) violation(EMode, "mode register bits above A9 are reserved (0)");
    cl        = c;
    wb_single = op[9];
    mode_set  = 1'b1;
    t_mrs     = cyc;
  endtask

  task automatic cmd_bst();
    check_common("BURST TERMINATE");
    if (wr_on) end_write();
    if (cl > 0) add_token(cyc + cl - 1, 1'b1, 1'b1, 0, 0, 0, 0);
  endtask

  // --------------------------------------------------------------------------------
  // One edge.
  task automatic edge_step();
    bit        nop;
    logic [2:0] rcw;
    cyc = cyc + 1;
    rcw = {ras_n_i, cas_n_i, we_n_i};
    lmr_now = 1'b0;
    nop = cs_n_i || rcw == 3'b111;
    if (!cke_i) violation(ECke, "CKE low (power-down / self refresh / clock suspend not modelled)");
    if (!nop && cyc < longint'(NInit)) begin
      violation(EInit, $sformatf("command %b during the power-up wait (%0d clocks)", rcw, NInit));
    end
    if (!nop) begin
      case (rcw)
        3'b011: cmd_active(int'(ba_i), int'(a_i[RowBits-1:0]));
        3'b101: cmd_rw(1'b0, int'(ba_i), int'(a_i[ColBits-1:0]), a_i[10]);
        3'b100: cmd_rw(1'b1, int'(ba_i), int'(a_i[ColBits-1:0]), a_i[10]);
        3'b010: cmd_precharge(a_i[10], int'(ba_i));
        3'b001: cmd_refresh();
        3'b000: cmd_lmr(a_i);
        3'b110: cmd_bst();
        default: ;
      endcase
    end

    // Write data of this edge.
    if (wr_on) begin
      int c;
      logic [15:0] old, nw;
      c = burst_col(wr_col, wr_idx, wr_len);
      old = mem.exists(key(wr_bank, wr_row, c)) ? mem[key(wr_bank, wr_row, c)] : UninitWord;
      nw  = {dqm_i[1] ? old[15:8] : dq_i[15:8], dqm_i[0] ? old[7:0] : dq_i[7:0]};
      if (dqm_i != 2'b11) begin
        mem[key(wr_bank, wr_row, c)] = nw;
        mem_is_pre = 1'b0;
      end
      // Write recovery runs from the last data-in edge, masked or not.
      t_wdata[wr_bank] = cyc;
      wr_idx = wr_idx + 1;
      if (wr_idx >= wr_len) end_write();
    end

    // Read data: advance the burst, then let the tokens due at this edge act.
    if (rd_on) begin
      rd_idx = rd_idx + 1;
      if (rd_idx >= rd_len) rd_on = 1'b0;
    end
    for (int k = 0; k < NTok; k++) begin
      if (tk_on[k] && tk_at[k] <= cyc) begin
        tk_on[k] = 1'b0;
        if (tk_stop[k]) begin
          if (rd_on && (tk_any[k] || tk_bank[k] == rd_bank)) rd_on = 1'b0;
        end else begin
          rd_on   = 1'b1;
          rd_bank = tk_bank[k];
          rd_row  = tk_row[k];
          rd_col  = tk_col[k];
          rd_len  = tk_len[k];
          rd_idx  = 0;
        end
      end
    end
    if (rd_on) begin
      int c;
      c = burst_col(rd_col, rd_idx, rd_len);
      dq_drv = mem.exists(key(rd_bank, rd_row, c)) ? mem[key(rd_bank, rd_row, c)] : UninitWord;
      // DQM two edges before the sampling edge (cyc + 1) masks the word.
      oe_drv = !(dqm_q1 == 2'b11);
    end else begin
      oe_drv = 1'b0;
    end
    dqm_q1 = dqm_i;
    if (lmr_now) begin
      bit pending;
      pending = rd_on;
      for (int k = 0; k < NTok; k++) pending |= tk_on[k] && !tk_stop[k];
      if (pending) violation(EMode, "LOAD MODE REGISTER while read data is still to come");
    end

    // Continuous checks: refresh interval, tRAS max.
    if (t_ref != Never && !ref_flagged && cyc - t_ref > longint'(NRefMax)) begin
      violation(ERefresh, $sformatf("no AUTO REFRESH for %0d clocks, max (%0d+1) x tREFI = %0d",
                                    cyc - t_ref, RefPostpone, NRefMax));
      ref_flagged = 1'b1;
    end
    for (int b = 0; b < NBanks; b++) begin
      if (active[b] && cyc - t_act[b] == longint'(NRasMax) + 1) begin
        violation(ETrasMax, $sformatf("bank %0d open for more than tRAS(max) = %0d clocks", b, NRasMax));
      end
    end
  endtask

  // The preload file (see the header): {addr, word} lines -> two 16-bit columns each.
  localparam int unsigned WordAddrBits = BankBits + RowBits + ColBits - 1;
  // A hex number of at most 16 digits; 0 if `t` is not one.
  function automatic bit parse_hex(input string t, output logic [63:0] v);
    v = '0;
    if (t.len() == 0 || t.len() > 16) return 1'b0;
    for (int i = 0; i < t.len(); i++) begin
      byte ch;
      ch = t[i];
      if (ch >= "0" && ch <= "9")      v = (v << 4) | 64'(ch - "0");
      else if (ch >= "a" && ch <= "f") v = (v << 4) | 64'(ch - "a" + 10);
      else if (ch >= "A" && ch <= "F") v = (v << 4) | 64'(ch - "A" + 10);
      else return 1'b0;
    end
    return 1'b1;
  endfunction

  task automatic read_preload(input string path);
    int    fd, lineno, words, ntok;
    string line, tok [3];
    logic [63:0] a, w;
    fd = $fopen(path, "r");
    if (fd == 0) $fatal(1, "sdram_sdr16: %s: cannot open the preload file", path);
    lineno = 0;
    words  = 0;
    while (!$feof(fd)) begin
      line = "";
      if ($fgets(line, fd) == 0) break;
      lineno++;
      while (line.len() > 0 && (line[line.len() - 1] == "\n" || line[line.len() - 1] == "\r"))
        line = line.substr(0, line.len() - 2);
      // Tokens up to the comment.
      ntok = 0;
      tok[0] = "";
      tok[1] = "";
      tok[2] = "";
      for (int i = 0; i < line.len(); i++) begin
        byte ch;
        ch = line[i];
        if (ch == "#") break;
        if (ch == " " || ch == "\t" || ch == "\n" || ch == "\r") begin
          if (ntok < 3 && tok[ntok] != "") ntok++;
        end else if (ntok < 3) begin
          tok[ntok] = {tok[ntok], string'(ch)};
        end else begin
          ntok = 4;
        end
      end
      if (ntok < 3 && tok[ntok] != "") ntok++;
      if (ntok == 0) continue;
      if (ntok != 2 || !parse_hex(tok[0], a) || !parse_hex(tok[1], w)) begin
        $fatal(1, "sdram_sdr16: %s:%0d: want '<addr> <word>' in hex, got '%s'", path,
               lineno, line);
      end
      if (a >> WordAddrBits != 0 || w >> 32 != 0) begin
        $fatal(1, "sdram_sdr16: %s:%0d: address %0h (%0d bits) or word %0h (32 bits) out of range",
               path, lineno, a, WordAddrBits, w);
      end
      pre[uint_t'(a) << 1]          = w[15:0];
      pre[(uint_t'(a) << 1) | 1'b1] = w[31:16];
      words++;
    end
    $fclose(fd);
    $display("sdram_sdr16: preloaded %0d words (%0d lines) from %s", words, lineno, path);
  endtask

  // The log file: LogFile, or +sdram_log=<path> on the simulator's command line.
  string log_name, image_name;
  initial begin
    log_fd   = 0;
    log_name = LogFile;
    void'($value$plusargs("sdram_log=%s", log_name));
    if (log_name != "") log_fd = $fopen(log_name, "w");
    image_name = PreloadFile;
    void'($value$plusargs("sdram_image=%s", image_name));
    if (image_name != "") read_preload(image_name);
    mem_is_pre = 1'b0;
    power_on();
    dq_o    = '0;
    dq_oe_o = 1'b0;
  end

  always @(posedge clk_i) begin
    if (rst_i) begin
      power_on();
    end else begin
      edge_step();
    end
    dq_o    <= dq_drv;
    dq_oe_o <= oe_drv;
  end

  assign err_count_o = err_count;
  assign err_seen_o  = err_seen;
  assign err_code_o  = err_code;
  assign cycle_o     = 32'(cyc + 1);
  assign init_done_o = pre_all_done && init_refs >= 2 && mode_set;
  assign ref_count_o = 32'(ref_count);
  assign cl_o        = 3'(cl);
  assign bl_o        = mode_set ? ((bl == 0) ? 10'(NCols) : 10'(bl)) : 10'd0;

endmodule

/* verilator lint_on WIDTH */
/* verilator lint_on BLKSEQ */
`default_nettype wire
