// Harness (built with Verilator) for the RTL unit benches: the combinational building blocks side by side, so
// that one model tests census, cost, aggregation step, sub-pixel and left-right check against the
// golden model's functions (fpga/sgm_rtl_units_test.cc).
module sgm_unit_bench (
    input  wire [199:0] census_win,
    output wire [11:0]  census_bits,
    input  wire [11:0]  cost_left,
    input  wire [383:0] cost_right,
    input  wire [31:0]  cost_outside,
    output wire [255:0] cost_out,
    input  wire [255:0] step_cost,
    input  wire [255:0] step_prev,
    input  wire [7:0]   step_prev_lo,
    input  wire [7:0]   step_prev_hi,
    input  wire [7:0]   step_min_prev,
    input  wire [7:0]   step_p1,
    input  wire [7:0]   step_p2,
    output wire [255:0] step_out,
    output wire [7:0]   step_min,
    input  wire [10:0]  sub_below,
    input  wire [10:0]  sub_at,
    input  wire [10:0]  sub_above,
    output wire [4:0]   sub_offset,
    input  wire [11:0]  lr_x,
    input  wire         lr_unique,
    input  wire [6:0]   lr_best,
    input  wire [15:0]  lr_value,
    input  wire [6:0]   lr_right_best,
    input  wire         lr_enable,
    input  wire [4:0]   lr_max_diff,
    output wire [15:0]  lr_disparity
);
  sgm_census5x5 u_census (.win(census_win), .bits(census_bits));
  sgm_cost_lanes #(.LANES(32)) u_cost (
      .left(cost_left), .right(cost_right), .outside(cost_outside), .cost(cost_out));
  sgm_path_step #(.LANES(32)) u_step (
      .cost(step_cost), .prev(step_prev), .prev_lo(step_prev_lo), .prev_hi(step_prev_hi),
      .min_prev(step_min_prev), .p1(step_p1), .p2(step_p2), .out(step_out), .word_min(step_min));
  wire signed [4:0] off;
  sgm_subpixel u_sub (.below(sub_below), .at(sub_at), .above(sub_above), .offset(off));
  assign sub_offset = off;
  sgm_lr_check #(.KBITS(7), .XBITS(12)) u_lr (
      .x(lr_x), .unique_best(lr_unique), .best(lr_best), .value(lr_value),
      .right_best(lr_right_best), .lr_enable(lr_enable), .lr_max_diff(lr_max_diff),
      .disparity(lr_disparity));
endmodule
