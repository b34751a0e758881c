// GENERATED FILE, DO NOT EDIT. Source: spec/isa.toml, spec/video.toml, spec/regs.toml.
// Regenerate with `python -m diffengine.isa.gen` (or `make gen`); `make gen-check` diffs.

`default_nettype none

// Difference Engine x-processor: shared widths, identifier layout, the block-carry
// adder, the instruction look-up table, the video modes and the debug-vector layout.
// docs/isa.md is the prose of spec/isa.toml; docs/display-controller.md 3 that of
// spec/video.toml.

package de_pkg;

  // A table package: not every block uses every entry, so Verilator's unused-parameter
  // warning would only list the entries other blocks use.
  /* verilator lint_off UNUSEDPARAM */

  // ---- widths ----
  localparam int unsigned IdW    = 12;
  localparam int unsigned BlkW   = 12;
  localparam int unsigned NumBlk = 3;
  localparam int unsigned DataW  = BlkW * NumBlk;
  localparam int unsigned FracW  = 24;
  localparam int unsigned PixW   = DataW - FracW;  // pixel = the integer part
  localparam int unsigned AddrMax = 4095;

  // ---- identifier fields ----
  localparam int unsigned IdAddrBit = 11;  // address slot (X / dX in the data)
  localparam int unsigned IdDataBit = 10;  // data slot (Eval value or Set)
  localparam int unsigned IdAccBit = 9;  // accumulate slot, D += A
  localparam int unsigned IdRefreshBit = 8;  // output the pixel, clear the PE
  localparam int unsigned IdDstLsb = 6;  // destination register code
  localparam int unsigned IdSrcLsb = 4;  // source register code
  localparam int unsigned IdSetBit = 3;  // data slot is a Set
  localparam int unsigned IdProtBit = 2;  // Eval data slot honours DST's protect flag
  localparam int unsigned IdSubLsb = 0;  // addressing sub-mode / Acc_mode

  // The same layout as a packed struct (MSB first), so that the RTL can write id.dst.
  typedef struct packed {
    logic       addr;
    logic       data;
    logic       acc;
    logic       refresh;
    logic [1:0] dst;
    logic [1:0] src;
    logic       set;
    logic       prot;
    logic [1:0] sub;
  } id_t;

  // ---- the array's chain from chip to chip (rtl/array/de_chip.sv) ----
  // What a chip passes to the next: the bus (skewed blocks), the pixel chain and the
  // chip's collision flag (MSB first). de_chip, its core and boundary registers and the
  // fast array's pieces (sim/fast) all pass this one value; a chip does not use the
  // coll of its input (the array ORs the chips' flags).
  typedef struct packed {
    logic [IdW-1:0]   id;
    logic [DataW-1:0] data;
    logic             pix_valid;
    logic [PixW-1:0]  pix;
    logic             coll;
  } link_t;
  // The configuration and observation chains: one serial bit each, chip to chip ...
  typedef struct packed {
    logic cfg;
    logic obs;
  } chain_t;
  // ... and their controls, the same for every chip: shift the configuration, load
  // and shift the observation words (7.4.5).
  typedef struct packed {
    logic cfg_mode;
    logic obs_load;
    logic obs_shift;
  } chain_ctl_t;

  // Register codes of the DST / SRC fields; RegNone reads as zero.
  localparam logic [1:0] RegNone = 2'd0;
  localparam logic [1:0] RegA = 2'd1;
  localparam logic [1:0] RegB = 2'd2;
  localparam logic [1:0] RegC = 2'd3;
  // SUB field codes (with ADDR set; Acc_mode with no class bit set).
  localparam logic [1:0] SubRange = 2'd0;
  localparam logic [1:0] SubPeriodic = 2'd1;
  localparam logic [1:0] SubEval0 = 2'd2;
  localparam logic [1:0] SubDis = 2'd3;
  localparam logic [1:0] SubAccmodeOn = 2'd1;
  localparam logic [1:0] SubAccmodeOff = 2'd2;

  // ---- identifiers of the look-up table ----
  localparam logic [IdW-1:0] IdNop = 12'h000;
  localparam logic [IdW-1:0] IdRefresh = 12'h100;
  localparam logic [IdW-1:0] IdAccmodeOn = 12'h001;
  localparam logic [IdW-1:0] IdAccmodeOff = 12'h002;
  localparam logic [IdW-1:0] IdAddrRange = 12'h800;
  localparam logic [IdW-1:0] IdAddrPeriodic = 12'h801;
  localparam logic [IdW-1:0] IdAddrEval0 = 12'h802;
  localparam logic [IdW-1:0] IdAddrDis = 12'h803;
  localparam logic [IdW-1:0] IdAcc = 12'h200;
  localparam logic [IdW-1:0] IdDA = 12'h444;
  localparam logic [IdW-1:0] IdDB = 12'h484;
  localparam logic [IdW-1:0] IdDC = 12'h4C4;
  localparam logic [IdW-1:0] IdDBC = 12'h4B4;
  localparam logic [IdW-1:0] IdDAB = 12'h464;
  localparam logic [IdW-1:0] IdDABNp = 12'h460;
  localparam logic [IdW-1:0] IdDAANp = 12'h450;
  localparam logic [IdW-1:0] IdSetA = 12'h448;
  localparam logic [IdW-1:0] IdSetB = 12'h488;
  localparam logic [IdW-1:0] IdSetC = 12'h4C8;

  // Operand type: how the data mapper expands the 27-bit operand.
  localparam logic [1:0] TypeNone = 2'd0;
  localparam logic [1:0] TypeAddress = 2'd1;
  localparam logic [1:0] TypeIntensity = 2'd2;
  localparam int unsigned LutCodeW = 5;

  // The prototype's 5 -> 12 look-up table; unused codes decode as Nop (cannot act).
  function automatic logic [IdW-1:0] lut_ident(input logic [LutCodeW-1:0] code);
    case (code)
      5'd0: lut_ident = IdNop;
      5'd1: lut_ident = IdRefresh;
      5'd2: lut_ident = IdAccmodeOn;
      5'd3: lut_ident = IdAccmodeOff;
      5'd4: lut_ident = IdAddrRange;
      5'd5: lut_ident = IdAddrPeriodic;
      5'd6: lut_ident = IdAddrEval0;
      5'd7: lut_ident = IdAddrDis;
      5'd8: lut_ident = IdAcc;
      5'd9: lut_ident = IdDA;
      5'd10: lut_ident = IdDB;
      5'd11: lut_ident = IdDC;
      5'd12: lut_ident = IdDBC;
      5'd13: lut_ident = IdDAB;
      5'd14: lut_ident = IdDABNp;
      5'd15: lut_ident = IdDAANp;
      5'd16: lut_ident = IdSetA;
      5'd17: lut_ident = IdSetB;
      5'd18: lut_ident = IdSetC;
      default: lut_ident = IdNop;
    endcase
  endfunction

  function automatic logic [1:0] lut_type(input logic [LutCodeW-1:0] code);
    case (code)
      5'd0, 5'd1, 5'd2, 5'd3, 5'd8:
        lut_type = TypeNone;
      5'd4, 5'd5, 5'd6, 5'd7:
        lut_type = TypeAddress;
      5'd9, 5'd10, 5'd11, 5'd12, 5'd13, 5'd14, 5'd15, 5'd16, 5'd17, 5'd18:
        lut_type = TypeIntensity;
      default: lut_type = TypeNone;
    endcase
  endfunction

  // ---- field selects ----
  // Register read port: code RegNone reads as zero ("adds 0"); a word, and through
  // it one block (de_pe) and a flag.
  function automatic logic [DataW-1:0] reg_word(input logic [1:0] code,
      input logic [DataW-1:0] a, input logic [DataW-1:0] b, input logic [DataW-1:0] c);
    case (code)
      RegA:    reg_word = a;
      RegB:    reg_word = b;
      RegC:    reg_word = c;
      default: reg_word = '0;
    endcase
  endfunction
  function automatic logic [BlkW-1:0] reg_blk(input logic [1:0] code, input logic [BlkW-1:0] a,
                                input logic [BlkW-1:0] b, input logic [BlkW-1:0] c);
    reg_blk = BlkW'(reg_word(code, DataW'(a), DataW'(b), DataW'(c)));
  endfunction
  function automatic logic reg_flag(input logic [1:0] code, input logic a,
                                input logic b, input logic c);
    reg_flag = 1'(reg_word(code, DataW'(a), DataW'(b), DataW'(c)));
  endfunction
  // One instruction as the y-processor and the controller store it: {identifier, data}.
  localparam int unsigned RecW = IdW + DataW;
  // Each reads one half of the record.
  /* verilator lint_off UNUSEDSIGNAL */
  function automatic logic [IdW-1:0] rec_id(input logic [RecW-1:0] r);
    rec_id = r[RecW-1 -: IdW];
  endfunction
  function automatic logic [DataW-1:0] rec_data(input logic [RecW-1:0] r);
    rec_data = r[DataW-1:0];
  endfunction
  /* verilator lint_on UNUSEDSIGNAL */
  // A command starts with a slot that is neither DATA nor ACC (an address slot,
  // Refresh, Acc_mode or Nop): the controller cuts the stream only there.
  function automatic logic id_starts_cmd(input logic [IdW-1:0] id);
    id_starts_cmd = !id[IdDataBit] && !id[IdAccBit];
  endfunction
  // Block i of a data word (block 0 = the low 12 bits; the pixel is block 2).
  function automatic logic [BlkW-1:0] word_blk(input logic [DataW-1:0] w,
                                               input int unsigned i);
    word_blk = w[i*BlkW +: BlkW];
  endfunction

  // ---- the adder (isa.md section 7) ----
  // With the prototype's carry fault the carry out of the fraction enters the integer
  // part at bit AddCarryTo instead of AddCarryFrom: it adds 2 where 1 was meant.
  localparam int unsigned AddCarryFrom = 24;
  localparam int unsigned AddCarryTo   = 25;
  localparam int unsigned AddCarryBlk  = AddCarryFrom / BlkW;  // block the fault enters

  // The whole-word form (de_span_array): one carry chain when carry_bug is 0.
  function automatic logic [DataW-1:0] add_word(input logic [DataW-1:0] x,
                                                input logic [DataW-1:0] y,
                                                input bit carry_bug);
    logic [AddCarryFrom:0]       lo;
    logic [DataW-AddCarryFrom-1:0] hi;
    lo = {1'b0, x[AddCarryFrom-1:0]} + {1'b0, y[AddCarryFrom-1:0]};
    hi = x[DataW-1:AddCarryFrom] + y[DataW-1:AddCarryFrom]
       + ((DataW - AddCarryFrom)'(lo[AddCarryFrom]) << (AddCarryTo - AddCarryFrom));
    // One carry chain without the fault: the fault's form puts two in series.
    add_word = carry_bug ? {hi, lo[AddCarryFrom-1:0]} : x + y;
  endfunction

  // The block-carry form (de_pe): weight of a registered block carry as it enters
  // block blk: bit 0, or with the fault bit AddCarryTo - AddCarryFrom of block
  // AddCarryBlk.
  function automatic logic [BlkW:0] blk_carry_in(input logic c, input int unsigned blk,
                                                input bit carry_bug);
    blk_carry_in = (BlkW + 1)'(c);
    if (carry_bug && blk == AddCarryBlk) begin
      blk_carry_in = (BlkW + 1)'(c) << (AddCarryTo - AddCarryFrom);
    end
  endfunction

  // ---- video modes (spec/video.toml) ----
  typedef struct packed {
    logic [11:0] h_act, h_fp, h_sync, h_bp;
    logic [11:0] v_act, v_fp, v_sync, v_bp;
    logic        h_pol, v_pol;  // 1 = active-high sync pulse
  } video_mode_t;
  localparam logic [1:0] VideoModeTest = 2'd3;
  // The test mode's default geometry (the tops' TestMode parameter).
  localparam video_mode_t VideoTestDefault = {12'd16, 12'd2, 12'd3, 12'd3,
                                            12'd6, 12'd1, 12'd2, 12'd2,
                                            1'b0, 1'b0};

  // The fixed modes by index; the test mode (and any other index) returns mode 0,
  // its geometry comes from de_video_timing's parameters.
  function automatic video_mode_t video_mode(input logic [1:0] m);
    case (m)
      // 640x480@60 (VESA DMT, 25.175 MHz, 800x525)
      2'd0: video_mode = {12'd640, 12'd16, 12'd96, 12'd48,
                         12'd480, 12'd10, 12'd2, 12'd33,
                         1'b0, 1'b0};
      // 640x485 low resolution of section 7.4.5 (21.5 MHz, 683x525, 59.96 Hz)
      2'd1: video_mode = {12'd640, 12'd8, 12'd24, 12'd11,
                         12'd485, 12'd11, 12'd2, 12'd27,
                         1'b0, 1'b0};
      // 1280x1024@60 (VESA DMT, 108 MHz, 1688x1066)
      2'd2: video_mode = {12'd1280, 12'd48, 12'd112, 12'd248,
                         12'd1024, 12'd1, 12'd3, 12'd38,
                         1'b1, 1'b1};
      default: video_mode = {12'd640, 12'd16, 12'd96, 12'd48,
                         12'd480, 12'd10, 12'd2, 12'd33,
                         1'b0, 1'b0};
    endcase
  endfunction

  // ---- de_pe's debug vector dbg_o (MSB first in spec/isa.toml) ----
  localparam int unsigned DbgALsb = 200;
  localparam int unsigned DbgBLsb = 164;
  localparam int unsigned DbgCLsb = 128;
  localparam int unsigned DbgDLsb = 92;
  localparam int unsigned DbgPaLsb = 91;
  localparam int unsigned DbgPbLsb = 90;
  localparam int unsigned DbgPcLsb = 89;
  localparam int unsigned DbgDisLsb = 88;
  localparam int unsigned DbgLockLsb = 87;
  localparam int unsigned DbgAccModeLsb = 86;
  localparam int unsigned DbgActLsb = 85;
  localparam int unsigned DbgId1Lsb = 73;
  localparam int unsigned DbgId2Lsb = 61;
  localparam int unsigned DbgOutLsb = 25;
  localparam int unsigned DbgXz1Lsb = 24;
  localparam int unsigned DbgAct1Lsb = 23;
  localparam int unsigned DbgProt1Lsb = 22;
  localparam int unsigned DbgC1Lsb = 21;
  localparam int unsigned DbgAct2Lsb = 20;
  localparam int unsigned DbgProt2Lsb = 19;
  localparam int unsigned DbgC2Lsb = 18;
  localparam int unsigned DbgE0wr2Lsb = 17;
  localparam int unsigned DbgAccen2Lsb = 16;
  localparam int unsigned DbgAccc2Lsb = 15;
  localparam int unsigned DbgAccen3Lsb = 14;
  localparam int unsigned DbgAccc3Lsb = 13;
  localparam int unsigned DbgPixValidLsb = 12;
  localparam int unsigned DbgPixLsb = 0;
  localparam int unsigned DbgW = 236;

  // ---- host register map (spec/regs.toml) ----
  localparam int unsigned RegChanLsb = 12;  // address bits above it: the channel
  localparam logic [1:0] RegInfoChan = 2'h3;  // channel of the controller's registers
  localparam logic [7:0] LmIdMagic = 8'hDE;  // Load Monitor ID[31:24]
  localparam logic [7:0] CtrlIdMagic = 8'hDC;  // controller ID[31:24]
  localparam logic [11:0] LmRegId = 12'h000;  // Load Monitor register
  localparam logic [11:0] LmRegFrames = 12'h001;  // Load Monitor register
  localparam logic [11:0] LmRegIssued = 12'h002;  // Load Monitor register
  localparam logic [11:0] LmRegFree = 12'h003;  // Load Monitor register
  localparam logic [11:0] LmRegLate = 12'h004;  // Load Monitor register
  localparam logic [11:0] LmRegDrop = 12'h005;  // Load Monitor register
  localparam logic [11:0] LmRegMaxIssued = 12'h006;  // Load Monitor register
  localparam logic [11:0] LmRegLastLine = 12'h007;  // Load Monitor register
  localparam logic [11:0] LmRegLastRec = 12'h008;  // Load Monitor register
  localparam logic [11:0] LmRegTotalDrop = 12'h009;  // Load Monitor register
  localparam logic [11:0] LmRegTotalLate = 12'h00A;  // Load Monitor register
  localparam logic [11:0] LmHistBase = 12'h040;  // HIST[b] at LM_HIST_BASE + b
  localparam logic [11:0] LmLineBase = 12'h400;  // LINE[l] at LM_LINE_BASE + l
  localparam logic [11:0] CtrlRegId = 12'h000;  // controller register
  localparam logic [11:0] CtrlRegAlignErr = 12'h001;  // controller register

  // Elaboration-time check that id_t and the bit positions above agree (used by de_pe).
  function automatic bit id_layout_ok();
    id_t t;
    bit  ok;
    ok = ($bits(t) == IdW);
    t = '0; t.addr = 1'b1; ok &= (IdW'(t) == IdW'(1) << IdAddrBit);
    t = '0; t.data = 1'b1; ok &= (IdW'(t) == IdW'(1) << IdDataBit);
    t = '0; t.acc = 1'b1; ok &= (IdW'(t) == IdW'(1) << IdAccBit);
    t = '0; t.refresh = 1'b1; ok &= (IdW'(t) == IdW'(1) << IdRefreshBit);
    t = '0; t.dst = 2'd1; ok &= (IdW'(t) == IdW'(1) << IdDstLsb);
    t = '0; t.src = 2'd1; ok &= (IdW'(t) == IdW'(1) << IdSrcLsb);
    t = '0; t.set = 1'b1; ok &= (IdW'(t) == IdW'(1) << IdSetBit);
    t = '0; t.prot = 1'b1; ok &= (IdW'(t) == IdW'(1) << IdProtBit);
    t = '0; t.sub = 2'd1; ok &= (IdW'(t) == IdW'(1) << IdSubLsb);
    id_layout_ok = ok;
  endfunction

  /* verilator lint_on UNUSEDPARAM */

endpackage

`default_nettype wire
