#pragma once
// Random packet loss on loopback TCP ports for integration tests: an nftables table of its own
// drops the given share of the packets to and from `ports`, at random, until destroyed. Needs
// root and nft; `why_not()` says why it could not be set up.

#include <cstdint>
#include <string>
#include <vector>

namespace cairn::testing {

// The packets counted by every `counter` in what `list_command` (an `nft list ...`) prints.
uint64_t NftCountedPackets(const std::string& list_command);

class LoopbackLoss {
 public:
  LoopbackLoss(const std::vector<int>& ports, int drop_percent);
  ~LoopbackLoss();
  LoopbackLoss(const LoopbackLoss&) = delete;
  LoopbackLoss& operator=(const LoopbackLoss&) = delete;

  const std::string& why_not() const { return why_not_; }
  uint64_t Dropped() const;  // packets its rules dropped so far

 private:
  std::string table_;
  std::string why_not_;
  bool created_ = false;
};

}  // namespace cairn::testing
