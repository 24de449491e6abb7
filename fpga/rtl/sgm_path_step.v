// One SGM recursion step for one disparity group of LANES lanes (the golden model's SgmPathStep):
//   out[k] = C[k] + min(prev[k], prev[k-1] + P1, prev[k+1] + P1, min_prev + P2) - min_prev
// with 8-bit sums saturating at 255 (only the 255 sentinels beyond the disparity range reach it).
// prev_lo is prev[k-1] of lane 0 and prev_hi prev[k+1] of the last lane (255 at the range ends).
// word_min = min over the lanes of out. Purely combinational: the horizontal path feeds its
// result back the next cycle.
module sgm_path_step #(
    parameter LANES = 32
) (
    input  wire [8*LANES-1:0] cost,
    input  wire [8*LANES-1:0] prev,
    input  wire [7:0]         prev_lo,
    input  wire [7:0]         prev_hi,
    input  wire [7:0]         min_prev,
    input  wire [7:0]         p1,
    input  wire [7:0]         p2,
    output wire [8*LANES-1:0] out,
    output wire [7:0]         word_min
);
  function [7:0] sat_add(input [7:0] a, input [7:0] b);
    reg [8:0] s;
    begin
      s = {1'b0, a} + {1'b0, b};
      sat_add = s[8] ? 8'hFF : s[7:0];
    end
  endfunction
  function [7:0] min8(input [7:0] a, input [7:0] b);
    min8 = a < b ? a : b;
  endfunction

  wire [7:0] jump = sat_add(min_prev, p2);
  wire [8*(LANES+2)-1:0] ext = {prev_hi, prev, prev_lo};  // ext lane j = prev lane j - 1
  genvar i;
  generate
    for (i = 0; i < LANES; i = i + 1) begin : g_lane
      wire [7:0] lm = sat_add(ext[8 * i +: 8], p1);
      wire [7:0] lp = sat_add(ext[8 * (i + 2) +: 8], p1);
      wire [7:0] m = min8(min8(prev[8 * i +: 8], jump), min8(lm, lp));
      assign out[8 * i +: 8] = cost[8 * i +: 8] + (m - min_prev);
    end
  endgenerate

  // Minimum tree over the lanes.
  localparam N = LANES;
  wire [7:0] tree [0:2*N-2] /*verilator split_var*/;
  generate
    for (i = 0; i < N; i = i + 1) begin : g_leaf
      assign tree[N - 1 + i] = out[8 * i +: 8];
    end
    for (i = N - 2; i >= 0; i = i - 1) begin : g_node
      assign tree[i] = min8(tree[2 * i + 1], tree[2 * i + 2]);
    end
  endgenerate
  assign word_min = tree[0];
endmodule
