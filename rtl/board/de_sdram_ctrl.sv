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
  parameter int unsigned BankBits   = 2,
  parameter int unsigned RowBits    = 13,
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
  // SDRAM pins (registered).
  output logic                sd_cke_o,
  output logic                sd_cs_n_o,
  output logic                sd_ras_n_o,
  output logic                sd_cas_n_o,
  output logic                sd_we_n_o,
  output logic [BankBits-1:0] sd_ba_o,
  output logic [PinAW-1:0]    sd_a_o,
  output logic [1:0]          sd_dqm_o,
  output logic [15:0]         sd_dq_o,
  output logic                sd_dq_oe_o,
  input  logic [15:0]         sd_dq_i
);
  // ---------------------------------------------------------------- parameter checks
  if (CasLatency != 2 && CasLatency != 3) begin : g_err_cl
    $error("de_sdram_ctrl: CasLatency must be 2 or 3");
  end
  if (RowBits < ColBits + 2 || RowBits < 11 || ColBits < 8) begin : g_err_geom
    $error("de_sdram_ctrl: RowBits >= ColBits + 2 (A10 and the column share the pins)");
  end
  if (TckPs < 5000) begin : g_err_tck
    $error("de_sdram_ctrl: TckPs >= 5000");
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

  if (NRefi < 64 || NRefi > 65535 || NInit > 1048575) begin : g_err_ref
    $error("de_sdram_ctrl: tREFI / tInit out of the counters' range");
  end

  // "since" counters saturate at 255 and read as "long ago"; a command in the clock
  // after another is 1 clock after it, so a gap of at least N clocks is since_q >= N - 1
  // (the M* thresholds).
  localparam int unsigned SW = 8;
  typedef logic [SW-1:0] since_t;
  localparam since_t MRcd   = since_t'(NRcd - 1);
  localparam since_t MRp    = since_t'(NRp - 1);
  localparam since_t MRas   = since_t'(NRas - 1);
  localparam since_t MRc    = since_t'(NRc - 1);
  localparam since_t MRrd   = since_t'(NRrd - 1);
  localparam since_t MRfc   = since_t'(NRfc - 1);
  localparam since_t MWr    = since_t'(NWr - 1);
  localparam since_t MMrd   = since_t'(NMrd - 1);
  localparam since_t MBl    = since_t'(NBl - 1);
  localparam since_t MRdWr  = since_t'(CasLatency + NBl - 1);

  if (NRc > 200 || NRfc > 200 || NRas > 200 || NRcd < 1 || NRp < 1 || NWr < 1 ||
      NMrd < 1) begin : g_err_since
    $error("de_sdram_ctrl: a timing is out of the 8-bit counters' range (1..200 clocks)");
  end

  function automatic logic [SW-1:0] inc(logic [SW-1:0] v);
    return (v == {SW{1'b1}}) ? v : v + 1'b1;
  endfunction

  // {cs_n, ras_n, cas_n, we_n}
  localparam logic [3:0] CmdNop   = 4'b0111;
  localparam logic [3:0] CmdAct   = 4'b0011;
  localparam logic [3:0] CmdRead  = 4'b0101;
  localparam logic [3:0] CmdWrite = 4'b0100;
  localparam logic [3:0] CmdPre   = 4'b0010;
  localparam logic [3:0] CmdRef   = 4'b0001;
  localparam logic [3:0] CmdLmr   = 4'b0000;

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

  // ---------------------------------------------------------------- state
  state_e state_d, state_q;
  logic [19:0] wait_d, wait_q;
  logic        init_ref_d, init_ref_q;     // the first init REF has gone
  logic [15:0] ref_cnt_d, ref_cnt_q;

  logic [NBanks-1:0]              open_d, open_q;
  logic [NBanks-1:0][RowBits-1:0] row_d, row_q;
  since_t [NBanks-1:0] s_act_d, s_act_q, s_pre_d, s_pre_q, s_rd_d, s_rd_q, s_wr_d, s_wr_q;
  since_t s_act_any_d, s_act_any_q, s_read_d, s_read_q, s_ref_d, s_ref_q, s_mrs_d, s_mrs_q;

  // The request being served.
  logic                cur_valid_d, cur_valid_q;
  logic                cur_write_d, cur_write_q;
  logic                cur_beat_d, cur_beat_q;       // write: high half next
  logic [AW-1:0]       cur_addr_d, cur_addr_q;
  logic [31:0]         cur_data_d, cur_data_q;
  logic [TagW-1:0]     cur_tag_d, cur_tag_q;

  // Pins.
  logic [3:0]          cmd_d, cmd_q;
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
  assign cur_bank = cur_addr_q[AW-1 -: BankBits];
  assign cur_row  = cur_addr_q[ColBits-1 +: RowBits];
  assign cur_colw = cur_addr_q[ColBits-2:0];

  logic accept;
  assign accept         = (state_q == SRun) && !cur_valid_q && (ref_cnt_q < 16'(NRefi));
  assign rd_req_ready_o = accept;
  assign wr_ready_o     = accept && !rd_req_valid_i;

  // ---------------------------------------------------------------- command decision
  logic hit, miss_open, can_act, can_pre, can_read, can_write, all_pre_ok, all_closed_ok;

  always_comb begin
    hit       = open_q[cur_bank] && (row_q[cur_bank] == cur_row);
    miss_open = open_q[cur_bank] && !hit;
    can_act   = (s_pre_q[cur_bank] >= MRp) && (s_act_q[cur_bank] >= MRc) &&
                (s_act_any_q >= MRrd) && (s_ref_q >= MRfc) && (s_mrs_q >= MMrd);
    // A PRECHARGE ends the bank's read data CasLatency-1 clocks later: not before the
    // 8 beats of its last READ are out.
    can_pre   = (s_act_q[cur_bank] >= MRas) && (s_wr_q[cur_bank] >= MWr) &&
                (s_rd_q[cur_bank] >= MBl);
    can_read  = hit && (s_act_q[cur_bank] >= MRcd) && (s_read_q >= MBl);
    // The write data must not meet read data on DQ: the last READ's beats are on the
    // bus until CasLatency + 7 clocks after it.
    can_write = hit && (s_act_q[cur_bank] >= MRcd) && (s_read_q >= MRdWr);
    all_pre_ok    = 1'b1;
    all_closed_ok = 1'b1;
    for (int unsigned b = 0; b < NBanks; b++) begin
      if (open_q[b] && !((s_act_q[b] >= MRas) && (s_wr_q[b] >= MWr) && (s_rd_q[b] >= MBl))) begin
        all_pre_ok = 1'b0;
      end
      if (s_pre_q[b] < MRp) all_closed_ok = 1'b0;
    end
  end

  always_comb begin
    state_d     = state_q;
    wait_d      = (wait_q != '0) ? wait_q - 1'b1 : wait_q;
    init_ref_d  = init_ref_q;
    ref_cnt_d   = (state_q == SInitWait || state_q == SInitPre || state_q == SInitRef ||
                   state_q == SInitLmr) ? '0 :
                  ((ref_cnt_q == '1) ? ref_cnt_q : ref_cnt_q + 1'b1);
    open_d      = open_q;
    row_d       = row_q;
    s_act_any_d = inc(s_act_any_q);
    s_read_d    = inc(s_read_q);
    s_ref_d     = inc(s_ref_q);
    s_mrs_d     = inc(s_mrs_q);
    for (int unsigned b = 0; b < NBanks; b++) begin
      s_act_d[b] = inc(s_act_q[b]);
      s_pre_d[b] = inc(s_pre_q[b]);
      s_rd_d[b]  = inc(s_rd_q[b]);
      s_wr_d[b]  = inc(s_wr_q[b]);
    end
    cur_valid_d = cur_valid_q;
    cur_write_d = cur_write_q;
    cur_beat_d  = cur_beat_q;
    cur_addr_d  = cur_addr_q;
    cur_data_d  = cur_data_q;
    cur_tag_d   = cur_tag_q;
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
        for (int unsigned b = 0; b < NBanks; b++) s_pre_d[b] = '0;
        state_d = SInitRef;
      end
      SInitRef: begin
        if (all_closed_ok && (s_ref_q >= MRfc)) begin
          cmd_d      = CmdRef;
          s_ref_d    = '0;
          init_ref_d = 1'b1;
          if (init_ref_q) state_d = SInitLmr;
        end
      end
      SInitLmr: begin
        if (s_ref_q >= MRfc) begin
          cmd_d   = CmdLmr;
          ba_d    = '0;
          a_d     = ModeWord;
          s_mrs_d = '0;
          state_d = SRun;
        end
      end
      SRun: begin
        if (!cur_valid_q) begin
          if (ref_cnt_q >= 16'(NRefi)) begin
            state_d = SRefPre;
          end else if (rd_req_valid_i) begin
            cur_valid_d = 1'b1;
            cur_write_d = 1'b0;
            cur_addr_d  = {rd_req_addr_i[AW-1:2], 2'b00};
            cur_tag_d   = rd_req_tag_i;
          end else if (wr_valid_i) begin
            cur_valid_d = 1'b1;
            cur_write_d = 1'b1;
            cur_beat_d  = 1'b0;
            cur_addr_d  = wr_addr_i;
            cur_data_d  = wr_data_i;
          end
        end else if (cur_write_q && cur_beat_q) begin
          // Second beat of a write: the high half, one column on, the next clock.
          cmd_d    = CmdWrite;
          ba_d     = cur_bank;
          a_d      = PinAW'({cur_colw, 1'b1});
          dq_d     = cur_data_q[31:16];
          dq_oe_d  = 1'b1;
          s_wr_d[cur_bank] = '0;
          cur_valid_d = 1'b0;
          cur_beat_d  = 1'b0;
        end else if (miss_open) begin
          if (can_pre) begin
            cmd_d = CmdPre;
            ba_d  = cur_bank;
            a_d   = '0;                                    // A10 = 0: this bank only
            open_d[cur_bank]  = 1'b0;
            s_pre_d[cur_bank] = '0;
          end
        end else if (!hit) begin
          if (can_act) begin
            cmd_d = CmdAct;
            ba_d  = cur_bank;
            a_d   = cur_row;
            open_d[cur_bank]  = 1'b1;
            row_d[cur_bank]   = cur_row;
            s_act_d[cur_bank] = '0;
            s_act_any_d       = '0;
          end
        end else if (cur_write_q) begin
          if (can_write) begin
            cmd_d   = CmdWrite;
            ba_d    = cur_bank;
            a_d     = PinAW'({cur_colw, 1'b0});
            dq_d    = cur_data_q[15:0];
            dq_oe_d = 1'b1;
            s_wr_d[cur_bank] = '0;
            cur_beat_d = 1'b1;
          end
        end else if (can_read) begin
          cmd_d = CmdRead;
          ba_d  = cur_bank;
          a_d   = PinAW'({cur_colw, 1'b0});
          s_rd_d[cur_bank] = '0;
          s_read_d    = '0;
          cur_valid_d = 1'b0;
        end
      end
      SRefPre: begin
        if (open_q == '0) begin
          state_d = SRef;
        end else if (all_pre_ok) begin
          cmd_d   = CmdPre;
          a_d     = '0;
          a_d[10] = 1'b1;
          for (int unsigned b = 0; b < NBanks; b++) begin
            if (open_q[b]) s_pre_d[b] = '0;
          end
          open_d  = '0;
          state_d = SRef;
        end
      end
      SRef: begin
        if (all_closed_ok && (s_ref_q >= MRfc)) begin
          cmd_d     = CmdRef;
          s_ref_d   = '0;
          ref_cnt_d = '0;
          refresh_o = 1'b1;
          state_d   = SRun;
        end
      end
      default: state_d = SInitWait;
    endcase
  end

  // ---------------------------------------------------------------- read data
  always_comb begin
    pipe_d = '0;
    for (int unsigned j = 0; j + 1 < PipeL; j++) pipe_d[j] = pipe_q[j + 1];
    if (cmd_d == CmdRead) begin
      // Beat i is on DQ at the SDRAM's edge READ + CasLatency + i, one clock after this
      // register sends the READ: pipe position CasLatency + i.
      for (int unsigned i = 0; i < NBl; i++) begin
        pipe_d[CasLatency + i].valid = 1'b1;
        pipe_d[CasLatency + i].odd   = i[0];
        pipe_d[CasLatency + i].last  = (i == NBl - 1);
        pipe_d[CasLatency + i].tag   = cur_tag_q;
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
    if (rst_i) begin
      state_q     <= SInitWait;
      wait_q      <= 20'(NInit);
      init_ref_q  <= 1'b0;
      ref_cnt_q   <= '0;
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
      cur_valid_q <= 1'b0;
      cur_write_q <= 1'b0;
      cur_beat_q  <= 1'b0;
      cur_addr_q  <= '0;
      cur_data_q  <= '0;
      cur_tag_q   <= '0;
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
      cur_valid_q <= cur_valid_d;
      cur_write_q <= cur_write_d;
      cur_beat_q  <= cur_beat_d;
      cur_addr_q  <= cur_addr_d;
      cur_data_q  <= cur_data_d;
      cur_tag_q   <= cur_tag_d;
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

  assign sd_cke_o    = cke_q;
  assign sd_cs_n_o   = cmd_q[3];
  assign sd_ras_n_o  = cmd_q[2];
  assign sd_cas_n_o  = cmd_q[1];
  assign sd_we_n_o   = cmd_q[0];
  assign sd_ba_o     = ba_q;
  assign sd_a_o      = a_q;
  assign sd_dqm_o    = 2'b00;
  assign sd_dq_o     = dq_q;
  assign sd_dq_oe_o  = dq_oe_q;
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
