// Instruction look-up table of the prototype's input circuit (Kuijk 1995, 7.6.2).
// A frame-store word carries a 5-bit code; the table turns it into the 12-bit
// instruction identifier the x-processors consume, plus the operand Type that tells
// the data mapper how to expand the 27-bit operand. Table contents: docs/isa.md 3.
`default_nettype none

module de_instr_lut (
  input  logic [4:0]  code_i,
  output logic [11:0] id_o,
  output logic [1:0]  type_o     // 0 none, 1 address (X/dX/I12), 2 intensity (36-bit)
);
  localparam logic [1:0] TNone = 2'd0;
  localparam logic [1:0] TAddr = 2'd1;
  localparam logic [1:0] TInt  = 2'd2;

  always_comb begin
    id_o = 12'h000;
    type_o  = TNone;
    unique case (code_i)
      5'd0:  begin id_o = 12'h000; type_o = TNone; end  // NOP
      5'd1:  begin id_o = 12'h100; type_o = TNone; end  // REFRESH
      5'd2:  begin id_o = 12'h001; type_o = TNone; end  // ACCMODE_ON
      5'd3:  begin id_o = 12'h002; type_o = TNone; end  // ACCMODE_OFF
      5'd4:  begin id_o = 12'h800; type_o = TAddr; end  // ADDR_RANGE
      5'd5:  begin id_o = 12'h801; type_o = TAddr; end  // ADDR_PERIODIC
      5'd6:  begin id_o = 12'h802; type_o = TAddr; end  // ADDR_EVAL0
      5'd7:  begin id_o = 12'h803; type_o = TAddr; end  // ADDR_DIS
      5'd8:  begin id_o = 12'h200; type_o = TNone; end  // ACC
      5'd9:  begin id_o = 12'h444; type_o = TInt;  end  // D_A
      5'd10: begin id_o = 12'h484; type_o = TInt;  end  // D_B
      5'd11: begin id_o = 12'h4C4; type_o = TInt;  end  // D_C
      5'd12: begin id_o = 12'h4B4; type_o = TInt;  end  // D_B_C
      5'd13: begin id_o = 12'h464; type_o = TInt;  end  // D_A_B
      5'd14: begin id_o = 12'h460; type_o = TInt;  end  // D_A_B_NP
      5'd15: begin id_o = 12'h450; type_o = TInt;  end  // D_A_A_NP
      5'd16: begin id_o = 12'h448; type_o = TInt;  end  // SET_A
      5'd17: begin id_o = 12'h488; type_o = TInt;  end  // SET_B
      5'd18: begin id_o = 12'h4C8; type_o = TInt;  end  // SET_C
      // Unused codes become Nop, so a corrupt frame-store word cannot act.
      default: begin id_o = 12'h000; type_o = TNone; end
    endcase
  end
endmodule

`default_nettype wire
