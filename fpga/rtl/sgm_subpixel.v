// Equiangular sub-pixel offset (the golden model's SgmSubpixelOffset) in 1/16 px:
//   off = round_half_away(8 (below - above) / (max(below, above) - at)), 0 if the denominator is 0.
// `at` is the smallest sum, so |below - above| <= denominator and |off| <= 8: four quotient bits
// from a restoring division. Purely combinational.
module sgm_subpixel (
    input  wire [10:0]       below,
    input  wire [10:0]       at,
    input  wire [10:0]       above,
    output wire signed [4:0] offset
);
  wire [10:0] hi = below > above ? below : above;
  wire [10:0] den = hi - at;
  wire [10:0] diff = below > above ? below - above : above - below;
  // numerator + den / 2 < 9 den <= 16 den
  wire [15:0] n0 = {2'b0, diff, 3'b0} + {6'b0, den[10:1]};
  wire [15:0] d0 = {5'b0, den};
  wire [15:0] s3 = d0 << 3, s2 = d0 << 2, s1 = d0 << 1;
  wire q3 = n0 >= s3;
  wire [15:0] n1 = q3 ? n0 - s3 : n0;
  wire q2 = n1 >= s2;
  wire [15:0] n2 = q2 ? n1 - s2 : n1;
  wire q1 = n2 >= s1;
  wire [15:0] n3 = q1 ? n2 - s1 : n2;
  wire q0 = n3 >= d0;
  wire [4:0] q = {1'b0, q3, q2, q1, q0};
  assign offset = den == 11'd0 ? 5'sd0 : (below >= above ? q : -q);
endmodule
