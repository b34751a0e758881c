// Instruction look-up table of the prototype's input circuit (Kuijk 1995, 7.6.2).
// A frame-store word carries a 5-bit code; the table turns it into the 12-bit
// instruction identifier the x-processors consume, plus the operand Type that tells
// the data mapper how to expand the 27-bit operand. Table contents: spec/isa.toml [lut]
// (docs/isa.md 3).
`default_nettype none

module de_instr_lut
  import de_pkg::*;
(
  input  logic [LutCodeW-1:0] code_i,
  output logic [IdW-1:0]      id_o,
  output logic [1:0]          type_o  // TypeNone, TypeAddress (X/dX/I12), TypeIntensity (36-bit)
);
  // The table is generated from spec/isa.toml into de_pkg (lut_ident, lut_type); unused
  // codes become Nop, so a corrupt frame-store word cannot act.
  assign id_o   = lut_ident(code_i);
  assign type_o = lut_type(code_i);
endmodule

`default_nettype wire
