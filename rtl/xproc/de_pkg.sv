// GENERATED FILE, DO NOT EDIT. Source: spec/isa.toml and spec/video.toml.
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
      5'd0: return IdNop;
      5'd1: return IdRefresh;
      5'd2: return IdAccmodeOn;
      5'd3: return IdAccmodeOff;
      5'd4: return IdAddrRange;
      5'd5: return IdAddrPeriodic;
      5'd6: return IdAddrEval0;
      5'd7: return IdAddrDis;
      5'd8: return IdAcc;
      5'd9: return IdDA;
      5'd10: return IdDB;
      5'd11: return IdDC;
      5'd12: return IdDBC;
      5'd13: return IdDAB;
      5'd14: return IdDABNp;
      5'd15: return IdDAANp;
      5'd16: return IdSetA;
      5'd17: return IdSetB;
      5'd18: return IdSetC;
      default: return IdNop;
    endcase
  endfunction

  function automatic logic [1:0] lut_type(input logic [LutCodeW-1:0] code);
    case (code)
      5'd0: return TypeNone;
      5'd1: return TypeNone;
      5'd2: return TypeNone;
      5'd3: return TypeNone;
      5'd4: return TypeAddress;
      5'd5: return TypeAddress;
      5'd6: return TypeAddress;
      5'd7: return TypeAddress;
      5'd8: return TypeNone;
      5'd9: return TypeIntensity;
      5'd10: return TypeIntensity;
      5'd11: return TypeIntensity;
      5'd12: return TypeIntensity;
      5'd13: return TypeIntensity;
      5'd14: return TypeIntensity;
      5'd15: return TypeIntensity;
      5'd16: return TypeIntensity;
      5'd17: return TypeIntensity;
      5'd18: return TypeIntensity;
      default: return TypeNone;
    endcase
  endfunction

  // ---- field selects ----
  // Register read port: code RegNone reads as zero ("adds 0"); one block, a word, a flag.
  function automatic logic [BlkW-1:0] reg_blk(input logic [1:0] code, input logic [BlkW-1:0] a,
                                input logic [BlkW-1:0] b, input logic [BlkW-1:0] c);
    case (code)
      RegA:    return a;
      RegB:    return b;
      RegC:    return c;
      default: return '0;
    endcase
  endfunction
  function automatic logic [DataW-1:0] reg_word(input logic [1:0] code, input logic [DataW-1:0] a,
                                input logic [DataW-1:0] b, input logic [DataW-1:0] c);
    case (code)
      RegA:    return a;
      RegB:    return b;
      RegC:    return c;
      default: return '0;
    endcase
  endfunction
  function automatic logic reg_flag(input logic [1:0] code, input logic a,
                                input logic b, input logic c);
    case (code)
      RegA:    return a;
      RegB:    return b;
      RegC:    return c;
      default: return 1'b0;
    endcase
  endfunction
  // Block i of a data word (block 0 = the low 12 bits; the pixel is block 2).
  function automatic logic [BlkW-1:0] word_blk(input logic [DataW-1:0] w,
                                               input int unsigned i);
    return w[i*BlkW +: BlkW];
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
    if (!carry_bug) return x + y;
    lo = {1'b0, x[AddCarryFrom-1:0]} + {1'b0, y[AddCarryFrom-1:0]};
    hi = x[DataW-1:AddCarryFrom] + y[DataW-1:AddCarryFrom]
       + ((DataW - AddCarryFrom)'(lo[AddCarryFrom]) << (AddCarryTo - AddCarryFrom));
    return {hi, lo[AddCarryFrom-1:0]};
  endfunction

  // The block-carry form (de_pe): weight of a registered block carry as it enters
  // block blk: bit 0, or with the fault bit AddCarryTo - AddCarryFrom of block
  // AddCarryBlk.
  function automatic logic [BlkW:0] blk_carry_in(input logic c, input int unsigned blk,
                                                input bit carry_bug);
    if (carry_bug && blk == AddCarryBlk) begin
      return (BlkW + 1)'(c) << (AddCarryTo - AddCarryFrom);
    end
    return (BlkW + 1)'(c);
  endfunction

  // ---- video modes (spec/video.toml) ----
  typedef struct packed {
    logic [11:0] h_act, h_fp, h_sync, h_bp;
    logic [11:0] v_act, v_fp, v_sync, v_bp;
    logic        h_pol, v_pol;  // 1 = active-high sync pulse
  } video_mode_t;
  localparam logic [1:0] VideoModeTest = 2'd3;

  // The fixed modes by index; the test mode (and any other index) returns mode 0,
  // its geometry comes from de_video_timing's parameters.
  function automatic video_mode_t video_mode(input logic [1:0] m);
    case (m)
      // 640x480@60 (VESA DMT, 25.175 MHz, 800x525)
      2'd0: return '{12'd640, 12'd16, 12'd96, 12'd48,
                     12'd480, 12'd10, 12'd2, 12'd33,
                     1'b0, 1'b0};
      // 640x485 low resolution of section 7.4.5 (21.5 MHz, 683x525, 59.96 Hz)
      2'd1: return '{12'd640, 12'd8, 12'd24, 12'd11,
                     12'd485, 12'd11, 12'd2, 12'd27,
                     1'b0, 1'b0};
      // 1280x1024@60 (VESA DMT, 108 MHz, 1688x1066)
      2'd2: return '{12'd1280, 12'd48, 12'd112, 12'd248,
                     12'd1024, 12'd1, 12'd3, 12'd38,
                     1'b1, 1'b1};
      default: return '{12'd640, 12'd16, 12'd96, 12'd48,
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

  // Elaboration-time check that id_t and the bit positions above agree (used by de_pe).
  function automatic bit id_layout_ok();
    id_t t;
    bit  ok;
    ok = ($bits(id_t) == IdW);
    t = '0; t.addr = 1'b1; ok &= (IdW'(t) == IdW'(1) << IdAddrBit);
    t = '0; t.data = 1'b1; ok &= (IdW'(t) == IdW'(1) << IdDataBit);
    t = '0; t.acc = 1'b1; ok &= (IdW'(t) == IdW'(1) << IdAccBit);
    t = '0; t.refresh = 1'b1; ok &= (IdW'(t) == IdW'(1) << IdRefreshBit);
    t = '0; t.dst = 2'd1; ok &= (IdW'(t) == IdW'(1) << IdDstLsb);
    t = '0; t.src = 2'd1; ok &= (IdW'(t) == IdW'(1) << IdSrcLsb);
    t = '0; t.set = 1'b1; ok &= (IdW'(t) == IdW'(1) << IdSetBit);
    t = '0; t.prot = 1'b1; ok &= (IdW'(t) == IdW'(1) << IdProtBit);
    t = '0; t.sub = 2'd1; ok &= (IdW'(t) == IdW'(1) << IdSubLsb);
    return ok;
  endfunction

  /* verilator lint_on UNUSEDPARAM */

endpackage

`default_nettype wire
