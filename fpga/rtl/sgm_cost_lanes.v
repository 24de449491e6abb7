// Hamming costs of one disparity group: lane i compares the left census with the right census of
// candidate i; a candidate outside the right image (border flag) costs all 12 census bits.
module sgm_cost_lanes #(
    parameter LANES = 32
) (
    input  wire [11:0]          left,
    input  wire [12*LANES-1:0]  right,
    input  wire [LANES-1:0]     outside,
    output wire [8*LANES-1:0]   cost
);
  genvar i;
  generate
    for (i = 0; i < LANES; i = i + 1) begin : g_lane
      wire [11:0] x = left ^ right[12 * i +: 12];
      wire [3:0] pop = {3'd0, x[0]} + {3'd0, x[1]} + {3'd0, x[2]} + {3'd0, x[3]} + {3'd0, x[4]} +
                       {3'd0, x[5]} + {3'd0, x[6]} + {3'd0, x[7]} + {3'd0, x[8]} + {3'd0, x[9]} +
                       {3'd0, x[10]} + {3'd0, x[11]};
      assign cost[8 * i +: 8] = outside[i] ? 8'd12 : {4'd0, pop};
    end
  endgenerate
endmodule
