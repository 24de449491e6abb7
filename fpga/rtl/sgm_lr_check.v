// The final decision of one left pixel x (the golden model's SgmMatcher::FinishRow): invalid
// (INT16_MIN) when the winner was not unique, matched outside the right image, or (with the check
// on) the right image's winner at x - d differs by more than lr_max_diff; else the winner with its
// sub-pixel offset (value, 1/16 px). Purely combinational.
module sgm_lr_check #(
    parameter KBITS = 7,
    parameter XBITS = 12
) (
    input  wire [XBITS-1:0]  x,
    input  wire              unique_best,
    input  wire [KBITS-1:0]  best,
    input  wire [15:0]       value,
    input  wire [KBITS-1:0]  right_best,
    input  wire              lr_enable,
    input  wire [4:0]        lr_max_diff,
    output wire [15:0]       disparity
);
  wire outside = {{(32 - KBITS){1'b0}}, best} > {{(32 - XBITS){1'b0}}, x};
  wire [KBITS-1:0] diff = best > right_best ? best - right_best : right_best - best;
  wire lr_fail = lr_enable && {{(32 - KBITS){1'b0}}, diff} > {27'd0, lr_max_diff};
  assign disparity = (!unique_best || outside || lr_fail) ? 16'h8000 : value;
endmodule
