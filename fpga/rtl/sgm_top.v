// The stereo offload as the host sees it: a 32-bit register file (PCIe BAR0 on the board, see
// fpga/REGISTERS.md), a DMA engine that reads the left and right images from host memory and
// writes the disparity image back, the census unit and the SGM core, and a level interrupt.
//
// Host memory interface (the PCIe DMA bridge on the board, the simulated host in cosimulation):
// 8-byte-aligned 64-bit reads with a tag (0 left, 1 right) answered in order per tag, and 64-bit
// writes with byte strobes. Either side can report an error (unmapped address, bus fault).
module sgm_top #(
    parameter LANES = 32,
    parameter DMAX = 128,
    parameter WMAX = 1024
) (
    input  wire        clk,
    input  wire        rst,
    // register bus: one access per cycle, read data the next cycle
    input  wire        reg_wr,
    input  wire        reg_rd,
    input  wire [11:0] reg_addr,
    input  wire [31:0] reg_wdata,
    output reg  [31:0] reg_rdata,
    output wire        irq,
    // DMA reads
    output wire        rd_req_valid,
    input  wire        rd_req_ready,
    output wire [63:0] rd_req_addr,
    output wire        rd_req_tag,
    input  wire        rd_resp_valid,
    input  wire [63:0] rd_resp_data,
    input  wire        rd_resp_tag,
    input  wire        rd_resp_err,
    // DMA writes
    output wire        wr_valid,
    input  wire        wr_ready,
    output wire [63:0] wr_addr,
    output wire [63:0] wr_data,
    output wire [7:0]  wr_strb,
    input  wire        wr_err
);
  localparam XBITS = 12;
  localparam [31:0] ID = 32'h53474D31;       // "SGM1"
  localparam [31:0] VERSION = 32'h00010000;  // 1.0
  localparam HMAX = 4095;

  // ---------------------------------------------------------------- registers
  reg [XBITS-1:0] width, height;
  reg [9:0] num_disp;
  reg [7:0] p1;
  reg [6:0] uniqueness;
  reg lr_enable, subpixel, irq_enable;
  reg [4:0] lr_max_diff;
  reg [63:0] src_left, src_right, dst;
  reg [31:0] src_stride, dst_stride;
  reg busy, done_flag, cfg_err, rd_err, wr_err_flag, overrun;
  reg [1:0] irq_status;  // bit 0 frame done, bit 1 error
  reg [31:0] cycles, last_in_cycles, tail_cycles;
  reg last_in_seen;

  wire wr_ctrl = reg_wr && reg_addr == 12'h010;
  wire start_req = wr_ctrl && reg_wdata[0];
  wire abort_req = wr_ctrl && reg_wdata[1];
  wire p2_we = reg_wr && reg_addr[11:10] == 2'b01;  // 0x400..0x7FC

  wire geometry_ok = width != 0 && {20'd0, width} <= WMAX && height != 0 &&
                     num_disp != 0 &&
                     num_disp % LANES == 0 && {22'd0, num_disp} <= DMAX &&
                     src_stride >= {20'd0, width} && dst_stride >= {19'd0, width, 1'b0} &&
                     src_left[2:0] == 0 && src_right[2:0] == 0 && dst[2:0] == 0 &&
                     src_stride[2:0] == 0 && dst_stride[2:0] == 0 && uniqueness <= 99;
  // A start waits until reads of an aborted frame have drained (their data is dropped).
  reg start_pend;
  reg [3:0] rd_outstanding;
  wire start_ok = start_pend && rd_outstanding == 0;
  wire fail = busy && (rd_resp_valid && rd_resp_err || wr_err);
  wire frame_done;
  wire in_last;  // the last input pixel enters the census unit
  wire core_rst = rst || start_ok || abort_req || fail;

  always @(posedge clk) begin
    if (rst) begin
      busy <= 0;
      start_pend <= 0;
      done_flag <= 0;
      cfg_err <= 0;
      rd_err <= 0;
      wr_err_flag <= 0;
      overrun <= 0;
      irq_status <= 0;
      irq_enable <= 0;
      cycles <= 0;
      width <= 0;
      height <= 0;
      num_disp <= 0;
    end else begin
      if (reg_wr) begin
        case (reg_addr)
          12'h010: irq_enable <= reg_wdata[8];
          12'h018: irq_status <= irq_status & ~reg_wdata[1:0];
          12'h020: width <= reg_wdata[XBITS-1:0];
          12'h024: height <= reg_wdata[XBITS-1:0];
          12'h028: num_disp <= reg_wdata[9:0];
          12'h02C: p1 <= reg_wdata[7:0];
          12'h030: uniqueness <= reg_wdata[6:0];
          12'h034: begin
            lr_enable <= reg_wdata[0];
            lr_max_diff <= reg_wdata[12:8];
          end
          12'h038: subpixel <= reg_wdata[0];
          12'h040: src_left[31:0] <= reg_wdata;
          12'h044: src_left[63:32] <= reg_wdata;
          12'h048: src_right[31:0] <= reg_wdata;
          12'h04C: src_right[63:32] <= reg_wdata;
          12'h050: src_stride <= reg_wdata;
          12'h054: dst[31:0] <= reg_wdata;
          12'h058: dst[63:32] <= reg_wdata;
          12'h05C: dst_stride <= reg_wdata;
          default: ;
        endcase
      end
      if (start_req) begin
        if (busy || start_pend) overrun <= 1;
        else if (!geometry_ok) begin
          cfg_err <= 1;
          irq_status[1] <= 1;
        end else start_pend <= 1;
      end
      if (start_ok) begin
        start_pend <= 0;
        busy <= 1;
        done_flag <= 0;
        cfg_err <= 0;
        rd_err <= 0;
        wr_err_flag <= 0;
        overrun <= 0;
        cycles <= 0;
        last_in_seen <= 0;
      end
      if (abort_req) begin
        busy <= 0;
        start_pend <= 0;
      end
      if (busy) cycles <= cycles + 1;
      if (fail) begin
        busy <= 0;
        if (rd_resp_valid && rd_resp_err) rd_err <= 1;
        if (wr_err) wr_err_flag <= 1;
        irq_status[1] <= 1;
      end else if (busy && frame_done) begin
        busy <= 0;
        done_flag <= 1;
        irq_status[0] <= 1;
        tail_cycles <= cycles - last_in_cycles;
      end
      if (busy && in_last && !last_in_seen) begin
        last_in_seen <= 1;
        last_in_cycles <= cycles;
      end
    end
  end
  assign irq = irq_enable && irq_status != 0;

  always @(posedge clk) begin
    case (reg_addr)
      12'h000: reg_rdata <= ID;
      12'h004: reg_rdata <= VERSION;
      12'h008: reg_rdata <= {LANES[15:0], DMAX[15:0]};
      12'h00C: reg_rdata <= {HMAX[15:0], WMAX[15:0]};
      12'h010: reg_rdata <= {23'd0, irq_enable, 8'd0};
      12'h014: reg_rdata <= {20'd0, overrun, wr_err_flag, rd_err, cfg_err, 5'd0,
                             cfg_err | rd_err | wr_err_flag | overrun, done_flag,
                             busy | start_pend};
      12'h018: reg_rdata <= {30'd0, irq_status};
      12'h020: reg_rdata <= {20'd0, width};
      12'h024: reg_rdata <= {20'd0, height};
      12'h028: reg_rdata <= {22'd0, num_disp};
      12'h02C: reg_rdata <= {24'd0, p1};
      12'h030: reg_rdata <= {25'd0, uniqueness};
      12'h034: reg_rdata <= {19'd0, lr_max_diff, 7'd0, lr_enable};
      12'h038: reg_rdata <= {31'd0, subpixel};
      12'h040: reg_rdata <= src_left[31:0];
      12'h044: reg_rdata <= src_left[63:32];
      12'h048: reg_rdata <= src_right[31:0];
      12'h04C: reg_rdata <= src_right[63:32];
      12'h050: reg_rdata <= src_stride;
      12'h054: reg_rdata <= dst[31:0];
      12'h058: reg_rdata <= dst[63:32];
      12'h05C: reg_rdata <= dst_stride;
      12'h060: reg_rdata <= cycles;
      12'h064: reg_rdata <= tail_cycles;
      default: reg_rdata <= 32'd0;
    endcase
  end

  // ---------------------------------------------------------------- DMA reads
  // Per image: request row by row, word by word; at most 4 words buffered or in flight.
  wire [XBITS-3:0] words_per_row = width[XBITS-1:3] + {{(XBITS-3){1'b0}}, width[2:0] != 0};
  reg [XBITS-1:0] q_row [0:1];
  reg [XBITS-3:0] q_word [0:1];
  reg [63:0] q_base [0:1];
  reg [2:0] q_credit [0:1];  // free slots: 4 - buffered - in flight
  reg q_done [0:1];
  reg rr;  // round robin
  wire want0 = busy && !q_done[0] && q_credit[0] != 0;
  wire want1 = busy && !q_done[1] && q_credit[1] != 0;
  wire pick = (want1 && (!want0 || rr));
  assign rd_req_valid = want0 || want1;
  assign rd_req_tag = pick;
  assign rd_req_addr = q_base[pick] + {{(64 - XBITS + 3){1'b0}}, q_word[pick], 3'b0};
  wire req_fire = rd_req_valid && rd_req_ready;

  always @(posedge clk) begin
    if (rst) rd_outstanding <= 0;
    else rd_outstanding <= rd_outstanding + {3'd0, req_fire} - {3'd0, rd_resp_valid};
  end

  // Word FIFOs and byte unpackers.
  reg [63:0] wf [0:1][0:3];
  reg [1:0] wf_rp [0:1], wf_wp [0:1];
  reg [2:0] wf_n [0:1];
  reg [XBITS-1:0] u_col [0:1];
  wire [63:0] head0 = wf[0][wf_rp[0]], head1 = wf[1][wf_rp[1]];
  wire pix_valid = wf_n[0] != 0 && wf_n[1] != 0;
  wire pix_ready;
  wire pix_take = pix_valid && pix_ready;
  wire [7:0] pix_l = head0[8 * u_col[0][2:0] +: 8];
  wire [7:0] pix_r = head1[8 * u_col[1][2:0] +: 8];
  wire word_end = u_col[0][2:0] == 3'd7 || u_col[0] == width - 1;
  reg [XBITS-1:0] in_row;
  assign in_last = pix_take && u_col[0] == width - 1 && in_row == height - 1;

  integer c;
  always @(posedge clk) begin
    if (core_rst) begin
      rr <= 0;
      in_row <= 0;
      for (c = 0; c < 2; c = c + 1) begin
        q_row[c] <= 0;
        q_word[c] <= 0;
        q_credit[c] <= 4;
        q_done[c] <= 0;
        wf_rp[c] <= 0;
        wf_wp[c] <= 0;
        wf_n[c] <= 0;
        u_col[c] <= 0;
      end
      q_base[0] <= src_left;
      q_base[1] <= src_right;
    end else begin
      if (req_fire) begin
        rr <= ~pick;
        if (q_word[pick] == words_per_row - 1) begin
          q_word[pick] <= 0;
          q_row[pick] <= q_row[pick] + 1;
          q_base[pick] <= q_base[pick] + {32'd0, src_stride};
          if (q_row[pick] == height - 1) q_done[pick] <= 1;
        end else q_word[pick] <= q_word[pick] + 1;
      end
      for (c = 0; c < 2; c = c + 1) begin
        q_credit[c] <= q_credit[c] - {2'd0, req_fire && pick == c} +
                       {2'd0, pix_take && word_end};
        wf_n[c] <= wf_n[c] + {2'd0, busy && rd_resp_valid && !rd_resp_err && rd_resp_tag == c} -
                   {2'd0, pix_take && word_end};
        if (pix_take) begin
          u_col[c] <= u_col[c] == width - 1 ? 0 : u_col[c] + 1;
          if (word_end) wf_rp[c] <= wf_rp[c] + 1;
        end
      end
      if (busy && rd_resp_valid && !rd_resp_err) begin
        wf[rd_resp_tag][wf_wp[rd_resp_tag]] <= rd_resp_data;
        wf_wp[rd_resp_tag] <= wf_wp[rd_resp_tag] + 1;
      end
      if (pix_take && u_col[0] == width - 1) in_row <= in_row + 1;
    end
  end

  // ---------------------------------------------------------------- census + core
  wire rec_valid, rec_pop;
  wire [31:0] rec_data;
  wire out_valid, out_ready, core_done;
  wire [15:0] out_data;
  sgm_census_unit #(.WMAX(WMAX), .XBITS(XBITS)) u_census (
      .clk(clk), .rst(core_rst), .width(width), .height(height), .in_valid(pix_valid && busy),
      .in_ready(pix_ready), .in_left(pix_l), .in_right(pix_r), .rec_valid(rec_valid),
      .rec_pop(rec_pop), .rec_data(rec_data));
  sgm_core #(.LANES(LANES), .DMAX(DMAX), .WMAX(WMAX), .XBITS(XBITS)) u_core (
      .clk(clk), .rst(core_rst), .width(width), .height(height),
      .ngroups(num_disp[9:0] / LANES), .p1(p1), .uniqueness(uniqueness), .lr_enable(lr_enable),
      .lr_max_diff(lr_max_diff), .subpixel(subpixel), .p2_we(p2_we), .p2_addr(reg_addr[9:2]),
      .p2_data(reg_wdata[7:0]), .rec_valid(rec_valid), .rec_pop(rec_pop), .rec_data(rec_data),
      .out_valid(out_valid), .out_ready(out_ready), .out_data(out_data), .done(core_done));

  // ---------------------------------------------------------------- DMA writes
  // Four disparities per 64-bit word; a row's last word carries only its valid lanes.
  reg [63:0] pk;
  reg [7:0] pk_strb;
  reg [XBITS-1:0] o_col, o_row;
  reg [63:0] o_base;
  reg w_pending;
  reg [63:0] w_addr, w_data;
  reg [7:0] w_strb;
  reg all_written;
  assign out_ready = busy && (!w_pending || wr_ready);
  wire o_take = out_valid && out_ready;
  wire o_word_end = o_col[1:0] == 2'd3 || o_col == width - 1;
  wire [63:0] pk_next = pk | ({48'd0, out_data} << (16 * o_col[1:0]));
  wire [7:0] strb_next = pk_strb | (8'd3 << (2 * o_col[1:0]));
  always @(posedge clk) begin
    if (core_rst) begin
      pk <= 0;
      pk_strb <= 0;
      o_col <= 0;
      o_row <= 0;
      o_base <= dst;
      w_pending <= 0;
      all_written <= 0;
    end else begin
      if (w_pending && wr_ready) begin
        w_pending <= 0;
        if (o_row == height) all_written <= 1;
      end
      if (o_take) begin
        if (o_word_end) begin
          w_pending <= 1;
          w_addr <= o_base + {{(64 - XBITS + 2){1'b0}}, o_col[XBITS-1:2], 3'b0};
          w_data <= pk_next;
          w_strb <= strb_next;
          pk <= 0;
          pk_strb <= 0;
        end else begin
          pk <= pk_next;
          pk_strb <= strb_next;
        end
        if (o_col == width - 1) begin
          o_col <= 0;
          o_row <= o_row + 1;
          o_base <= o_base + {32'd0, dst_stride};
        end else o_col <= o_col + 1;
      end
    end
  end
  assign wr_valid = w_pending;
  assign wr_addr = w_addr;
  assign wr_data = w_data;
  assign wr_strb = w_strb;
  assign frame_done = all_written && core_done;
endmodule
