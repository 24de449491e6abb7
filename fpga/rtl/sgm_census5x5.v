// Centre-symmetric census of one 5x5 window (12 pixel pairs), the golden model's bit order: pairs
// (dx, dy) in raster order before the centre, first pair in the most significant bit, bit set when
// I(x+dx, y+dy) > I(x-dx, y-dy). win[8*(5*r + c) +: 8] is the pixel at row r, column c (r = 2,
// c = 2 is the centre). Purely combinational.
module sgm_census5x5 (
    /* verilator lint_off UNUSEDSIGNAL */
    input  wire [199:0] win,  // the centre pixel is not compared
    /* verilator lint_on UNUSEDSIGNAL */
    output wire [11:0]  bits
);
  genvar i;
  generate
    for (i = 0; i < 12; i = i + 1) begin : g_pair
      // Pair i: window index i (raster order) against its mirror 24 - i.
      wire [7:0] a = win[8 * i +: 8];
      wire [7:0] b = win[8 * (24 - i) +: 8];
      assign bits[11 - i] = a > b;
    end
  endgenerate
endmodule
