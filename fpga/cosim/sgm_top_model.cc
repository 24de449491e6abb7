#include "fpga/cosim/sgm_top_model.h"

#include "Vsgm_top.h"
#include "verilated.h"

namespace cairn {

struct SgmTopModel::Impl {
  VerilatedContext context;
  Vsgm_top top{&context};
};

namespace {

SgmTopOutputs Read(const Vsgm_top& t) {
  SgmTopOutputs o;
  o.reg_rdata = t.reg_rdata;
  o.irq = t.irq;
  o.rd_req_valid = t.rd_req_valid;
  o.rd_req_addr = t.rd_req_addr;
  o.rd_req_tag = t.rd_req_tag;
  o.wr_valid = t.wr_valid;
  o.wr_addr = t.wr_addr;
  o.wr_data = t.wr_data;
  o.wr_strb = t.wr_strb;
  return o;
}

}  // namespace

SgmTopModel::SgmTopModel() : impl_(std::make_unique<Impl>()) {
  Vsgm_top& t = impl_->top;
  t.clk = 0;
  t.eval();
}

SgmTopModel::~SgmTopModel() { impl_->top.final(); }

SgmTopOutputs SgmTopModel::Cycle(const SgmTopInputs& in) {
  Vsgm_top& t = impl_->top;
  t.clk = 0;
  t.rst = in.rst;
  t.reg_wr = in.reg_wr;
  t.reg_rd = in.reg_rd;
  t.reg_addr = in.reg_addr;
  t.reg_wdata = in.reg_wdata;
  t.rd_req_ready = in.rd_req_ready;
  t.rd_resp_valid = in.rd_resp_valid;
  t.rd_resp_data = in.rd_resp_data;
  t.rd_resp_tag = in.rd_resp_tag;
  t.rd_resp_err = in.rd_resp_err;
  t.wr_ready = in.wr_ready;
  t.wr_err = in.wr_err;
  t.eval();
  const SgmTopOutputs before = Read(t);
  t.clk = 1;
  t.eval();
  ++cycles_;
  return before;
}

SgmTopOutputs SgmTopModel::Outputs() const { return Read(impl_->top); }

}  // namespace cairn
