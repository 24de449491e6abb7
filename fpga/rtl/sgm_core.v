// Streaming SGM aggregation, winner-take-all, sub-pixel refinement and left-right check (the
// golden model's raster_paths mode, bit for bit). One "beat" handles one disparity group of LANES
// disparities of one pixel; the beats run in raster order, group by group:
//
//   S0 issue    pop the pixel's census record (first group), shift the right census line,
//               look up the four P2' penalties from the intensity steps
//   S1 cost     Hamming costs of the group; read the upper rows' path words for the next beat
//   S2 paths    left-to-right, up-left, up and up-right recursion steps (sgm_path_step)
//   S3 sum      sum of the four paths
//   S4 select   argmin over the groups; minimum per right pixel along the diagonal; second pass
//               over the previous pixel's sums (uniqueness, sub-pixel neighbours)
//   S5 decide   uniqueness test and sub-pixel offset -> left decision row buffer
//   checker     one row behind: left-right check against the finished right winners -> output
//
// Row buffers for the path words, the decisions and the right winners are sized by WMAX and DMAX;
// width, height, disparity count (ngroups * LANES), P1, the P2' table, uniqueness and the LR
// check are run-time inputs held stable by sgm_top during a frame.
module sgm_core #(
    parameter LANES = 32,
    parameter DMAX = 128,
    parameter WMAX = 1024,
    parameter XBITS = 12
) (
    input  wire             clk,
    input  wire             rst,
    input  wire [XBITS-1:0] width,
    input  wire [XBITS-1:0] height,
    input  wire [4:0]       ngroups,
    input  wire [7:0]       p1,
    input  wire [6:0]       uniqueness,
    input  wire             lr_enable,
    input  wire [4:0]       lr_max_diff,
    input  wire             subpixel,
    input  wire             p2_we,
    input  wire [7:0]       p2_addr,
    input  wire [7:0]       p2_data,
    input  wire             rec_valid,
    output wire             rec_pop,
    input  wire [31:0]      rec_data,
    output wire             out_valid,
    input  wire             out_ready,
    output wire [15:0]      out_data,
    output wire             done
);
  localparam GMAX = DMAX / LANES;
  localparam GB = GMAX > 1 ? $clog2(GMAX) : 1;
  localparam KB = $clog2(DMAX);
  localparam LB = $clog2(LANES);
  localparam AW = $clog2(WMAX);
  localparam VW = 8 * LANES;
  localparam SW = 11 * LANES;
  localparam MW = AW + GB;  // path word address: {x, group}

  integer i;

  // P2' per absolute intensity step, written by the host (the golden model's p2 table).
  reg [7:0] p2t [0:255];
  always @(posedge clk) if (p2_we) p2t[p2_addr] <= p2_data;

  wire [GB-1:0] last_group = ngroups[GB-1:0] - 1'b1;
  wire [XBITS-1:0] last_x = width - 1'b1;

  // ------------------------------------------------------------------ S0: issue
  reg [XBITS-1:0] bx, by;
  reg [GB-1:0] bg;
  reg issued_all;
  reg [XBITS:0] rows_checked, rows_decided;
  wire dummy0 = by == height;  // one extra pixel flushes the last row's second pass
  wire need_rec = bg == 0 && !dummy0;
  wire row_ok = bx != 0 || bg != 0 || dummy0 || {1'b0, by} < rows_checked + 2;
  wire issue = !issued_all && row_ok && (!need_rec || rec_valid);
  assign rec_pop = issue && need_rec;
  wire [7:0] rec_i = rec_data[31:24];
  wire [11:0] rec_cl = rec_data[23:12], rec_cr = rec_data[11:0];

  always @(posedge clk) begin
    if (rst) begin
      bx <= 0;
      by <= 0;
      bg <= 0;
      issued_all <= 0;
    end else if (issue) begin
      if (bg == last_group) begin
        bg <= 0;
        if (dummy0) issued_all <= 1;
        else if (bx == last_x) begin
          bx <= 0;
          by <= by + 1'b1;
        end else bx <= bx + 1'b1;
      end else bg <= bg + 1'b1;
    end
  end

  // Right census of x - k for k < DMAX, with an "outside the image" flag; left census, intensity.
  reg [12:0] rc [0:DMAX-1];
  reg [11:0] cl;
  reg [7:0] il;
  // Left intensities of the current and the previous row (by row parity).
  reg [7:0] ibuf [0:2*WMAX-1];
  reg [7:0] p2h, p2u, p2ul, p2ur;
  wire [XBITS-1:0] xl = bx == 0 ? bx : bx - 1'b1;
  wire [XBITS-1:0] xr1 = bx == last_x ? bx : bx + 1'b1;
  wire [7:0] up_c = ibuf[{~by[0], bx[AW-1:0]}];
  wire [7:0] up_l = ibuf[{~by[0], xl[AW-1:0]}];
  wire [7:0] up_r = ibuf[{~by[0], xr1[AW-1:0]}];
  function [7:0] absdiff(input [7:0] a, input [7:0] b);
    absdiff = a > b ? a - b : b - a;
  endfunction
  genvar gk;
  generate
    for (gk = 1; gk < DMAX; gk = gk + 1) begin : g_rc_shift
      always @(posedge clk) if (rec_pop) rc[gk] <= bx == 0 ? 13'h1000 : rc[gk - 1];
    end
  endgenerate
  always @(posedge clk) begin
    if (rec_pop) begin
      rc[0] <= {1'b0, rec_cr};
      cl <= rec_cl;
      il <= rec_i;
      ibuf[{by[0], bx[AW-1:0]}] <= rec_i;
      p2h <= p2t[absdiff(rec_i, il)];
      p2u <= p2t[absdiff(rec_i, up_c)];
      p2ul <= p2t[absdiff(rec_i, up_l)];
      p2ur <= p2t[absdiff(rec_i, up_r)];
    end
  end

  // ------------------------------------------------------------------ S1: cost
  reg s1_v, s1_dummy;
  reg [XBITS-1:0] s1_x, s1_y;
  reg [GB-1:0] s1_g;
  always @(posedge clk) begin
    if (rst) s1_v <= 0;
    else s1_v <= issue;
    s1_dummy <= dummy0;
    s1_x <= bx;
    s1_y <= by;
    s1_g <= bg;
  end
  wire [12*LANES-1:0] rc_grp;
  wire [LANES-1:0] rc_out;
  genvar gl;
  generate
    for (gl = 0; gl < LANES; gl = gl + 1) begin : g_rc
      wire [12:0] e = rc[(s1_g * LANES + gl) % DMAX];
      assign rc_grp[12 * gl +: 12] = e[11:0];
      assign rc_out[gl] = e[12];
    end
  endgenerate
  wire [VW-1:0] cost1;
  sgm_cost_lanes #(.LANES(LANES)) u_cost (.left(cl), .right(rc_grp), .outside(rc_out), .cost(cost1));

  // Path words of the row above: one memory per vertical path, read one beat ahead (the
  // successor of the S1 beat) so that S2 has its group and the next one.
  wire s1_last = s1_g == last_group;
  wire [XBITS-1:0] nx = s1_last ? (s1_x == last_x ? {XBITS{1'b0}} : s1_x + 1'b1) : s1_x;
  wire [GB-1:0] ng = s1_last ? {GB{1'b0}} : s1_g + 1'b1;
  wire [XBITS-1:0] nx_l = nx == 0 ? nx : nx - 1'b1;
  wire [XBITS-1:0] nx_r = nx == last_x ? nx : nx + 1'b1;
  reg [VW-1:0] vm_u [0:(1<<MW)-1];
  reg [VW-1:0] vm_ul [0:(1<<MW)-1];
  reg [VW-1:0] vm_ur [0:(1<<MW)-1];
  reg [VW-1:0] rd_u, rd_ul, rd_ur;
  always @(posedge clk) begin
    if (s1_v) begin
      rd_u <= vm_u[{nx[AW-1:0], ng}];
      rd_ul <= vm_ul[{nx_l[AW-1:0], ng}];
      rd_ur <= vm_ur[{nx_r[AW-1:0], ng}];
    end
  end

  // ------------------------------------------------------------------ S2: paths
  reg s2_v, s2_dummy;
  reg [XBITS-1:0] s2_x, s2_y;
  reg [GB-1:0] s2_g;
  reg [VW-1:0] s2_cost;
  reg [7:0] s2_p2h, s2_p2u, s2_p2ul, s2_p2ur;
  always @(posedge clk) begin
    if (rst) s2_v <= 0;
    else s2_v <= s1_v;
    s2_dummy <= s1_dummy;
    s2_x <= s1_x;
    s2_y <= s1_y;
    s2_g <= s1_g;
    s2_cost <= cost1;
    s2_p2h <= p2h;
    s2_p2u <= p2u;
    s2_p2ul <= p2ul;
    s2_p2ur <= p2ur;
  end
  wire s2_live = s2_v && !s2_dummy;
  wire s2_first = s2_g == 0;
  wire s2_last = s2_g == last_group;
  function [7:0] min8(input [7:0] a, input [7:0] b);
    min8 = a < b ? a : b;
  endfunction

  // Left-to-right: the previous pixel's words, held in registers.
  reg [VW-1:0] hvec [0:GMAX-1];
  reg [7:0] h_last, h_run, h_min;
  wire [GB-1:0] s2_gn = s2_g + 1'b1;
  wire h_zero = s2_x == 0;
  wire [VW-1:0] h_prev = h_zero ? {VW{1'b0}} : hvec[s2_g % GMAX];
  wire [VW-1:0] h_next = hvec[s2_gn % GMAX];
  wire [VW-1:0] h_out;
  wire [7:0] h_wmin;
  sgm_path_step #(.LANES(LANES)) u_h (
      .cost(s2_cost), .prev(h_prev), .prev_lo(s2_first ? 8'hFF : h_last),
      .prev_hi(s2_last ? 8'hFF : h_next[7:0]), .min_prev(h_zero ? 8'd0 : h_min), .p1(p1),
      .p2(s2_p2h), .out(h_out), .word_min(h_wmin));
  wire [7:0] h_fin = s2_first ? h_wmin : min8(h_run, h_wmin);

  // The three paths from the row above. A = this beat's word, rd_* = the next one.
  reg [VW-1:0] a_u, a_ul, a_ur;
  reg [7:0] l_u, l_ul, l_ur;   // last lane of the previous group
  reg [7:0] r_u, r_ul, r_ur;   // running minima
  reg [7:0] vmin_u [0:WMAX-1];
  reg [7:0] vmin_ul [0:WMAX-1];
  reg [7:0] vmin_ur [0:WMAX-1];
  wire z_u = s2_y == 0;
  wire z_ul = s2_y == 0 || s2_x == 0;
  wire z_ur = s2_y == 0 || s2_x == last_x;
  wire [XBITS-1:0] s2_xl = s2_x - 1'b1, s2_xr = s2_x + 1'b1;
  wire [7:0] m_u = z_u ? 8'd0 : vmin_u[s2_x[AW-1:0]];
  wire [7:0] m_ul = z_ul ? 8'd0 : vmin_ul[s2_xl[AW-1:0]];
  wire [7:0] m_ur = z_ur ? 8'd0 : vmin_ur[s2_xr[AW-1:0]];
  wire [VW-1:0] o_u, o_ul, o_ur;
  wire [7:0] w_u, w_ul, w_ur;
  sgm_path_step #(.LANES(LANES)) u_up (
      .cost(s2_cost), .prev(z_u ? {VW{1'b0}} : a_u), .prev_lo(s2_first ? 8'hFF : l_u),
      .prev_hi(s2_last ? 8'hFF : rd_u[7:0]), .min_prev(m_u), .p1(p1), .p2(s2_p2u),
      .out(o_u), .word_min(w_u));
  sgm_path_step #(.LANES(LANES)) u_upl (
      .cost(s2_cost), .prev(z_ul ? {VW{1'b0}} : a_ul), .prev_lo(s2_first ? 8'hFF : l_ul),
      .prev_hi(s2_last ? 8'hFF : rd_ul[7:0]), .min_prev(m_ul), .p1(p1), .p2(s2_p2ul),
      .out(o_ul), .word_min(w_ul));
  sgm_path_step #(.LANES(LANES)) u_upr (
      .cost(s2_cost), .prev(z_ur ? {VW{1'b0}} : a_ur), .prev_lo(s2_first ? 8'hFF : l_ur),
      .prev_hi(s2_last ? 8'hFF : rd_ur[7:0]), .min_prev(m_ur), .p1(p1), .p2(s2_p2ur),
      .out(o_ur), .word_min(w_ur));
  wire [7:0] f_u = s2_first ? w_u : min8(r_u, w_u);
  wire [7:0] f_ul = s2_first ? w_ul : min8(r_ul, w_ul);
  wire [7:0] f_ur = s2_first ? w_ur : min8(r_ur, w_ur);

  // The up-left words of pixel x are still needed by pixel x + 1 of the next row, which reads
  // address x - 1 after this row has passed it: they are written one pixel late.
  reg [VW-1:0] dly [0:GMAX-1];
  reg [AW-1:0] dly_x;
  reg dly_v;
  reg [7:0] dly_min;

  always @(posedge clk) begin
    if (rst) begin
      dly_v <= 0;
    end else if (s2_v) begin
      a_u <= rd_u;
      a_ul <= rd_ul;
      a_ur <= rd_ur;
      l_u <= a_u[VW-8 +: 8];
      l_ul <= a_ul[VW-8 +: 8];
      l_ur <= a_ur[VW-8 +: 8];
      if (s2_live) begin
        hvec[s2_g % GMAX] <= h_out;
        h_last <= h_prev[VW-8 +: 8];
        h_run <= h_fin;
        r_u <= f_u;
        r_ul <= f_ul;
        r_ur <= f_ur;
        vm_u[{s2_x[AW-1:0], s2_g}] <= o_u;
        vm_ur[{s2_x[AW-1:0], s2_g}] <= o_ur;
        if (dly_v) vm_ul[{dly_x, s2_g}] <= dly[s2_g % GMAX];
        dly[s2_g % GMAX] <= o_ul;
        if (s2_last) begin
          h_min <= h_fin;
          vmin_u[s2_x[AW-1:0]] <= f_u;
          vmin_ur[s2_x[AW-1:0]] <= f_ur;
          if (dly_v) vmin_ul[dly_x] <= dly_min;
          dly_min <= f_ul;
          dly_x <= s2_x[AW-1:0];
          dly_v <= 1;
        end
      end
    end
  end

  // ------------------------------------------------------------------ S3: sum of the paths
  reg s3_v, s3_dummy;
  reg [XBITS-1:0] s3_x, s3_y;
  reg [GB-1:0] s3_g;
  reg [VW-1:0] s3_h, s3_u, s3_ul, s3_ur;
  always @(posedge clk) begin
    if (rst) s3_v <= 0;
    else s3_v <= s2_v;
    s3_dummy <= s2_dummy;
    s3_x <= s2_x;
    s3_y <= s2_y;
    s3_g <= s2_g;
    s3_h <= h_out;
    s3_u <= o_u;
    s3_ul <= o_ul;
    s3_ur <= o_ur;
  end
  wire [SW-1:0] sum3;
  generate
    for (gl = 0; gl < LANES; gl = gl + 1) begin : g_sum
      assign sum3[11 * gl +: 11] = {3'd0, s3_h[8 * gl +: 8]} + {3'd0, s3_u[8 * gl +: 8]} +
                                   {3'd0, s3_ul[8 * gl +: 8]} + {3'd0, s3_ur[8 * gl +: 8]};
    end
  endgenerate

  // ------------------------------------------------------------------ S4: selection
  reg s4_v, s4_dummy;
  reg [XBITS-1:0] s4_x, s4_y;
  reg [GB-1:0] s4_g;
  reg [SW-1:0] s4_sum;
  always @(posedge clk) begin
    if (rst) s4_v <= 0;
    else s4_v <= s3_v;
    s4_dummy <= s3_dummy;
    s4_x <= s3_x;
    s4_y <= s3_y;
    s4_g <= s3_g;
    s4_sum <= sum3;
  end
  wire s4_live = s4_v && !s4_dummy;
  wire s4_first = s4_g == 0;
  wire s4_last = s4_g == last_group;

  // Pass 1: argmin of this pixel.
  wire [10:0] wmin;
  wire [LB-1:0] wlane;
  sgm_argmin #(.LANES(LANES), .LB(LB)) u_argmin (.values(s4_sum), .min_value(wmin), .min_lane(wlane));
  reg [10:0] best_m;
  reg [KB-1:0] best_k;
  wire [KB-1:0] wk = s4_g * LANES + wlane;
  wire take = s4_first || wmin < best_m;
  wire [10:0] fin_m = take ? wmin : best_m;
  wire [KB-1:0] fin_k = take ? wk : best_k;

  // Sums of the last two pixels (by pixel parity) for the second pass.
  reg [SW-1:0] sbuf [0:(2<<GB)-1];
  reg pp;
  reg pend_v, pend_pp;
  reg [10:0] pend_m;
  reg [KB-1:0] pend_k;
  reg [XBITS-1:0] pend_x, pend_y;
  // Pass 2 over the pending (previous) pixel: smallest sum outside best +- 1, and the sums beside
  // the winner.
  wire [SW-1:0] pw = sbuf[{pend_pp, s4_g}];
  reg [10:0] sec_w, below_w, above_w;
  reg below_hit, above_hit;
  always @(*) begin
    sec_w = 11'h7FF;
    below_w = 0;
    above_w = 0;
    below_hit = 0;
    above_hit = 0;
    for (i = 0; i < LANES; i = i + 1) begin
      // k = g * LANES + i; keep when k + 1 < best or k > best + 1
      if ((s4_g * LANES + i + 1 < pend_k) || (s4_g * LANES + i > pend_k + 1)) begin
        if (pw[11 * i +: 11] < sec_w) sec_w = pw[11 * i +: 11];
      end
      if (s4_g * LANES + i + 1 == pend_k) begin
        below_w = pw[11 * i +: 11];
        below_hit = 1;
      end
      if (s4_g * LANES + i == pend_k + 1) begin
        above_w = pw[11 * i +: 11];
        above_hit = 1;
      end
    end
  end
  reg [10:0] sec_run, below_r, above_r;
  wire [10:0] sec_fin = s4_first || sec_w < sec_run ? sec_w : sec_run;
  wire [10:0] below_fin = below_hit ? below_w : below_r;
  wire [10:0] above_fin = above_hit ? above_w : above_r;

  // Right winners: rarr[k] = running {min sum, disparity} of right pixel x - k; the entry leaving
  // the end is final and goes to the row buffer rw, the rest at the row end to tail.
  reg [10:0] rarr_m [0:DMAX-1];
  reg [KB-1:0] rarr_k [0:DMAX-1];
  reg [KB-1:0] rw [0:2*WMAX-1];
  reg [KB-1:0] tail [0:2*DMAX-1];
  wire row_start4 = s4_first && (s4_x == 0 || s4_dummy);
  wire [XBITS-1:0] s4_xe = s4_x - DMAX[XBITS-1:0];
  wire [XBITS-1:0] s4_yp = s4_y - 1'b1;

  reg d5_v;
  reg [XBITS-1:0] d5_x, d5_y;
  reg [KB-1:0] d5_k;
  reg [10:0] d5_m, d5_sec, d5_below, d5_above;

  always @(posedge clk) begin
    if (rst) begin
      pp <= 0;
      pend_v <= 0;
      d5_v <= 0;
    end else begin
      d5_v <= 0;
      if (s4_v) begin
        // pass 2
        if (pend_v) begin
          sec_run <= sec_fin;
          below_r <= below_fin;
          above_r <= above_fin;
          if (s4_last) begin
            d5_v <= 1;
            d5_x <= pend_x;
            d5_y <= pend_y;
            d5_k <= pend_k;
            d5_m <= pend_m;
            d5_sec <= sec_fin;
            d5_below <= below_fin;
            d5_above <= above_fin;
            pend_v <= 0;
          end
        end
        // pass 1
        if (s4_live) begin
          sbuf[{pp, s4_g}] <= s4_sum;
          best_m <= fin_m;
          best_k <= fin_k;
          if (s4_last) begin
            pend_v <= 1;
            pend_pp <= pp;
            pend_m <= fin_m;
            pend_k <= fin_k;
            pend_x <= s4_x;
            pend_y <= s4_y;
            pp <= ~pp;
          end
        end
        // right winners: the entry leaving the array is final
        if (s4_first && !row_start4 && s4_x >= DMAX) begin
          rw[{s4_y[0], s4_xe[AW-1:0]}] <= rarr_k[DMAX-1];
        end
      end
    end
  end
  generate
    for (gk = 0; gk < DMAX; gk = gk + 1) begin : g_rarr
      // At a row start the finished row's winners go to tail, and the array restarts.
      always @(posedge clk) begin
        if (s4_v && row_start4 && s4_y != 0) tail[{s4_yp[0], gk[KB-1:0]}] <= rarr_k[gk];
      end
      wire shift_in = s4_first && (row_start4 || gk == 0);
      wire [10:0] bm = shift_in ? 11'h7FF : (s4_first ? rarr_m[gk == 0 ? 0 : gk - 1] : rarr_m[gk]);
      wire [KB-1:0] bk = shift_in ? {KB{1'b0}} : (s4_first ? rarr_k[gk == 0 ? 0 : gk - 1] : rarr_k[gk]);
      wire [10:0] c = s4_sum[11 * (gk % LANES) +: 11];
      wire upd = s4_live && (gk / LANES) == s4_g && c < bm;
      always @(posedge clk) begin
        if (s4_v) begin
          rarr_m[gk] <= upd ? c : bm;
          rarr_k[gk] <= upd ? gk[KB-1:0] : bk;
        end
      end
    end
  endgenerate

  // ------------------------------------------------------------------ S5: decision
  wire signed [4:0] sub_off;
  sgm_subpixel u_sub (.below(d5_below), .at(d5_m), .above(d5_above), .offset(sub_off));
  wire [KB-1:0] last_k = ngroups * LANES - 1;
  wire use_sub = subpixel && d5_k != 0 && d5_k != last_k;
  wire [17:0] lhs = {7'd0, d5_sec} * (7'd100 - uniqueness);
  wire [17:0] rhs = {7'd0, d5_m} * 7'd100;
  wire uniq_ok = lhs >= rhs;
  wire [15:0] value = {{(12 - KB){1'b0}}, d5_k, 4'b0} + (use_sub ? {{11{sub_off[4]}}, sub_off} : 16'd0);
  reg [KB+16:0] ld [0:2*WMAX-1];  // {unique, winner, value}
  always @(posedge clk) begin
    if (rst) begin
      rows_decided <= 0;
    end else if (d5_v) begin
      ld[{d5_y[0], d5_x[AW-1:0]}] <= {uniq_ok, d5_k, value};
      if (d5_x == last_x) rows_decided <= rows_decided + 1'b1;
    end
  end

  // ------------------------------------------------------------------ checker (one row behind)
  // c0 reads the decision, c1 the right winner at x - d, c2 decides and pushes.
  reg [3:0] ocount;
  wire cen = ocount <= 4'd5;
  reg [XBITS-1:0] cy, cx;
  reg c1_v, c2_v;
  reg [XBITS-1:0] c1_x, c2_x;
  reg c1_b;
  reg [KB+16:0] c1_ld, c2_ld;
  reg [KB-1:0] c2_rw, c2_tl;
  reg c2_tail;
  wire c0 = cen && {1'b0, cy} < rows_decided;
  wire [KB-1:0] c1_k = c1_ld[KB+15:16];
  wire [XBITS-1:0] c1_xr = c1_x - {{(XBITS - KB){1'b0}}, c1_k};
  wire [XBITS-1:0] c1_ti = last_x - c1_xr;  // tail index W - 1 - xr
  wire [15:0] disp;
  sgm_lr_check #(.KBITS(KB), .XBITS(XBITS)) u_lr (
      .x(c2_x), .unique_best(c2_ld[KB+16]), .best(c2_ld[KB+15:16]), .value(c2_ld[15:0]),
      .right_best(c2_tail ? c2_tl : c2_rw), .lr_enable(lr_enable), .lr_max_diff(lr_max_diff),
      .disparity(disp));
  reg [15:0] ofifo [0:7];
  reg [2:0] orp, owp;
  wire opush = cen && c2_v;
  wire opop = out_ready && ocount != 0;
  always @(posedge clk) begin
    if (rst) begin
      cy <= 0;
      cx <= 0;
      c1_v <= 0;
      c2_v <= 0;
      rows_checked <= 0;
      orp <= 0;
      owp <= 0;
      ocount <= 0;
    end else begin
      if (cen) begin
        c1_v <= c0;
        c1_x <= cx;
        c1_b <= cy[0];
        if (c0) begin
          if (cx == last_x) begin
            cx <= 0;
            cy <= cy + 1'b1;
          end else cx <= cx + 1'b1;
          c1_ld <= ld[{cy[0], cx[AW-1:0]}];
        end
        c2_v <= c1_v;
        c2_x <= c1_x;
        c2_ld <= c1_ld;
        c2_rw <= rw[{c1_b, c1_xr[AW-1:0]}];
        c2_tl <= tail[{c1_b, c1_ti[KB-1:0]}];
        c2_tail <= {1'b0, c1_ti} < DMAX;
        if (c2_v && c2_x == last_x) rows_checked <= rows_checked + 1'b1;
      end
      if (opush) begin
        ofifo[owp] <= disp;
        owp <= owp + 1'b1;
      end
      if (opop) orp <= orp + 1'b1;
      ocount <= ocount + {3'd0, opush} - {3'd0, opop};
    end
  end
  assign out_valid = ocount != 0;
  assign out_data = ofifo[orp];
  assign done = rows_checked == {1'b0, height} && ocount == 0;
endmodule
