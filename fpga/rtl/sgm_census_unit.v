// Line buffers and the 5x5 census of both images. Pixels (left, right) arrive in raster order;
// eight row slots per image hold the rows the census window needs (rows y-2..y+2, replicated at
// the image borders) while the next rows arrive. The census of each pixel (and its left
// intensity) goes to a small FIFO that the aggregation core pops once per pixel.
module sgm_census_unit #(
    parameter WMAX = 1024,
    parameter XBITS = 12
) (
    input  wire             clk,
    input  wire             rst,        // synchronous, also used between frames
    input  wire [XBITS-1:0] width,
    input  wire [XBITS-1:0] height,
    input  wire             in_valid,
    output wire             in_ready,
    input  wire [7:0]       in_left,
    input  wire [7:0]       in_right,
    output wire             rec_valid,
    input  wire             rec_pop,
    output wire [31:0]      rec_data    // {left intensity, left census, right census}
);
  localparam AW = $clog2(WMAX);

  // ---- writer: row slot wr_row % 8 ----
  reg [XBITS-1:0] wr_row, wr_col;
  reg [XBITS-1:0] cy;  // census row being produced
  wire can_write = wr_row < height && wr_row <= cy + 5;
  assign in_ready = can_write;
  wire write = in_valid && can_write;
  always @(posedge clk) begin
    if (rst) begin
      wr_row <= 0;
      wr_col <= 0;
    end else if (write) begin
      if (wr_col == width - 1) begin
        wr_col <= 0;
        wr_row <= wr_row + 1;
      end else begin
        wr_col <= wr_col + 1;
      end
    end
  end

  // ---- reader: W + 4 column reads per row, clamp(j - 2) ----
  reg [XBITS:0] j;          // read counter of the current row
  reg           row_active;
  reg [3:0]     fifo_count;
  wire [XBITS-1:0] last_row = height - 1;
  wire [XBITS-1:0] need_row = (cy + 2 > last_row) ? last_row : cy + 2;
  wire rows_ready = wr_row > need_row;
  wire adv = fifo_count <= 4'd5;  // room for the two records in flight
  wire issue = adv && row_active && rows_ready;
  wire signed [XBITS+1:0] col_s = $signed({1'b0, j}) - 2;
  /* verilator lint_off UNUSEDSIGNAL */
  wire [XBITS-1:0] col = col_s < 0 ? {XBITS{1'b0}} :
                         (col_s >= $signed({2'b0, width}) ? width - 1 : col_s[XBITS-1:0]);
  /* verilator lint_on UNUSEDSIGNAL */

  // Row slots of the five window rows.
  /* verilator lint_off UNUSEDSIGNAL */
  function [2:0] slot_of(input signed [XBITS+1:0] r);
    reg signed [XBITS+1:0] c;
    begin
      c = r < 0 ? 0 : (r > $signed({2'b0, last_row}) ? $signed({2'b0, last_row}) : r);
      slot_of = c[2:0];
    end
  endfunction
  /* verilator lint_on UNUSEDSIGNAL */

  reg [2:0] win_slot [0:4];
  integer r;
  always @(posedge clk) begin
    if (rst) begin
      cy <= 0;
      j <= 0;
      row_active <= 1;
    end else if (issue) begin
      if (j == {1'b0, width} + 3) begin
        j <= 0;
        cy <= cy + 1;
        row_active <= cy + 1 < height;
      end else begin
        j <= j + 1;
      end
    end
  end
  // The slots are fixed for the row being read; registered with the read so that they match the
  // data.
  reg [2:0] rd_slot [0:4];
  always @(*) begin
    for (r = 0; r < 5; r = r + 1) begin
      win_slot[r] = slot_of($signed({2'b0, cy}) + $signed(r[XBITS+1:0]) - 2);
    end
  end

  // Eight memories per image, one per row slot; all read the same column.
  wire [7:0] q_l [0:7];
  wire [7:0] q_r [0:7];
  genvar s;
  generate
    for (s = 0; s < 8; s = s + 1) begin : g_slot
      reg [7:0] mem_l [0:WMAX-1];
      reg [7:0] mem_r [0:WMAX-1];
      reg [7:0] rd_l, rd_r;
      always @(posedge clk) begin
        if (write && wr_row[2:0] == s) begin
          mem_l[wr_col[AW-1:0]] <= in_left;
          mem_r[wr_col[AW-1:0]] <= in_right;
        end
        if (issue) begin
          rd_l <= mem_l[col[AW-1:0]];
          rd_r <= mem_r[col[AW-1:0]];
        end
      end
      assign q_l[s] = rd_l;
      assign q_r[s] = rd_r;
    end
  endgenerate

  // Stage 1: shift the read column into the windows. Stage 2: census.
  reg v1, v2;
  reg [XBITS:0] j1, j2;
  reg [199:0] win_l, win_r;  // 5 rows x 5 columns, column 4 newest
  always @(posedge clk) begin
    if (rst) begin
      v1 <= 0;
      v2 <= 0;
    end else if (adv) begin
      v1 <= issue;
      j1 <= j;
      for (r = 0; r < 5; r = r + 1) if (issue) rd_slot[r] <= win_slot[r];
      v2 <= v1;
      j2 <= j1;
      if (v1) begin
        for (r = 0; r < 5; r = r + 1) begin
          win_l[40 * r +: 40] <= {q_l[rd_slot[r]], win_l[40 * r + 8 +: 32]};
          win_r[40 * r +: 40] <= {q_r[rd_slot[r]], win_r[40 * r + 8 +: 32]};
        end
      end
    end
  end
  wire [11:0] cen_l, cen_r;
  sgm_census5x5 u_cl (.win(win_l), .bits(cen_l));
  sgm_census5x5 u_cr (.win(win_r), .bits(cen_r));
  wire push = adv && v2 && j2 >= 4;

  // Record FIFO (8 deep).
  reg [31:0] fifo [0:7];
  reg [2:0] rp, wp;
  always @(posedge clk) begin
    if (rst) begin
      rp <= 0;
      wp <= 0;
      fifo_count <= 0;
    end else begin
      if (push) begin
        fifo[wp] <= {win_l[12 * 8 +: 8], cen_l, cen_r};
        wp <= wp + 1;
      end
      if (rec_pop && fifo_count != 0) rp <= rp + 1;
      fifo_count <= fifo_count + {3'd0, push} - {3'd0, rec_pop && fifo_count != 0};
    end
  end
  assign rec_valid = fifo_count != 0;
  assign rec_data = fifo[rp];
endmodule
