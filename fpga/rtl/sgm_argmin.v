// Smallest value of LANES 11-bit values and its lane, the lowest lane on ties (the golden model's
// winner-take-all order). Purely combinational tree.
module sgm_argmin #(
    parameter LANES = 32,
    parameter LB = 5
) (
    input  wire [11*LANES-1:0] values,
    output wire [10:0]         min_value,
    output wire [LB-1:0]       min_lane
);
  localparam N = LANES;
  wire [10:0]   v [0:2*N-2] /*verilator split_var*/;
  wire [LB-1:0] k [0:2*N-2] /*verilator split_var*/;
  genvar i;
  generate
    for (i = 0; i < N; i = i + 1) begin : g_leaf
      assign v[N - 1 + i] = values[11 * i +: 11];
      assign k[N - 1 + i] = i[LB-1:0];
    end
    for (i = N - 2; i >= 0; i = i - 1) begin : g_node
      // Left child holds the lower lanes: it wins ties.
      wire right_wins = v[2 * i + 2] < v[2 * i + 1];
      assign v[i] = right_wins ? v[2 * i + 2] : v[2 * i + 1];
      assign k[i] = right_wins ? k[2 * i + 2] : k[2 * i + 1];
    end
  endgenerate
  assign min_value = v[0];
  assign min_lane = k[0];
endmodule
