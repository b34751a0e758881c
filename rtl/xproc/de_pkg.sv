// Difference Engine x-processor: shared widths and identifier layout.
//
// docs/isa.md section 3 is the normative identifier table; sw/diffengine/isa.py is its
// Python form. Keep the three in step.

package de_pkg;

  // ---- widths ----------------------------------------------------------------------
  localparam int unsigned IdW    = 12;            // instruction identifier
  localparam int unsigned BlkW   = 12;            // one block of the data word
  localparam int unsigned NumBlk = 3;             // blocks per data word
  localparam int unsigned DataW  = BlkW * NumBlk; // 36-bit 12.24 fixed point
  localparam int unsigned PixW   = BlkW;          // pixel = D[35:24]

  // ---- identifier bit positions (isa.md section 3) -----------------------------------
  localparam int unsigned IdAddrBit    = 11;  // address slot (X / dX in the data)
  localparam int unsigned IdDataBit    = 10;  // data slot (Eval value or Set)
  localparam int unsigned IdAccBit     = 9;   // accumulate slot, D += A
  localparam int unsigned IdRefreshBit = 8;   // output the pixel, clear the PE
  localparam int unsigned IdDstLsb     = 6;   // [7:6] destination register code
  localparam int unsigned IdSrcLsb     = 4;   // [5:4] source register code
  localparam int unsigned IdSetBit     = 3;   // data slot is a Set
  localparam int unsigned IdProtBit    = 2;   // Eval data slot honours DST's protect flag
  localparam int unsigned IdSubLsb     = 0;   // [1:0] addressing sub-mode / Acc_mode

  // The same layout as a packed struct (MSB first), so that the RTL can write id.dst.
  typedef struct packed {
    logic       addr;     // 11
    logic       data;     // 10
    logic       acc;      // 9
    logic       refresh;  // 8
    logic [1:0] dst;      // 7:6
    logic [1:0] src;      // 5:4
    logic       set;      // 3
    logic       prot;     // 2
    logic [1:0] sub;      // 1:0
  } id_t;

  // Register codes of the DST / SRC fields.
  localparam logic [1:0] RegNone = 2'd0;
  localparam logic [1:0] RegA    = 2'd1;
  localparam logic [1:0] RegB    = 2'd2;
  localparam logic [1:0] RegC    = 2'd3;

  // SUB field with ADDR set.
  // Every sub-mode but SubPeriodic uses range addressing, so the RTL never compares
  // with SubRange; it stays here as the table entry.
  /* verilator lint_off UNUSEDPARAM */
  localparam logic [1:0] SubRange    = 2'd0;
  /* verilator lint_on UNUSEDPARAM */
  localparam logic [1:0] SubPeriodic = 2'd1;
  localparam logic [1:0] SubEval0    = 2'd2;
  localparam logic [1:0] SubDis      = 2'd3;
  // SUB field with no class bit set.
  localparam logic [1:0] SubAccModeOn  = 2'd1;
  localparam logic [1:0] SubAccModeOff = 2'd2;

  // Elaboration-time check that id_t and the bit positions above agree (used by de_pe).
  function automatic bit id_layout_ok();
    id_t t;
    bit  ok;
    ok = ($bits(id_t) == IdW);
    t = '0; t.addr    = 1'b1; ok &= (IdW'(t) == IdW'(1) << IdAddrBit);
    t = '0; t.data    = 1'b1; ok &= (IdW'(t) == IdW'(1) << IdDataBit);
    t = '0; t.acc     = 1'b1; ok &= (IdW'(t) == IdW'(1) << IdAccBit);
    t = '0; t.refresh = 1'b1; ok &= (IdW'(t) == IdW'(1) << IdRefreshBit);
    t = '0; t.dst     = 2'd1; ok &= (IdW'(t) == IdW'(1) << IdDstLsb);
    t = '0; t.src     = 2'd1; ok &= (IdW'(t) == IdW'(1) << IdSrcLsb);
    t = '0; t.set     = 1'b1; ok &= (IdW'(t) == IdW'(1) << IdSetBit);
    t = '0; t.prot    = 1'b1; ok &= (IdW'(t) == IdW'(1) << IdProtBit);
    t = '0; t.sub     = 2'd1; ok &= (IdW'(t) == IdW'(1) << IdSubLsb);
    return ok;
  endfunction

  // Width of de_pe's debug vector dbg_o; its layout is DBG_FIELDS in
  // sw/diffengine/structural.py (4x36 registers, 7 flags, 2x12 ids, 36 out, 12 pipeline
  // bits, pixel valid + 12).
  // Modules without a de_pe (de_span_array) import the package but not this width.
  /* verilator lint_off UNUSEDPARAM */
  localparam int unsigned DbgW = 4 * DataW + 7 + 2 * IdW + DataW + 12 + 1 + PixW;
  /* verilator lint_on UNUSEDPARAM */

endpackage
