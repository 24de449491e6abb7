#include "tests/support/loopback_loss.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace cairn::testing {
namespace {

bool Run(const std::string& command) { return std::system((command + " >/dev/null 2>&1").c_str()) == 0; }

}  // namespace

LoopbackLoss::LoopbackLoss(const std::vector<int>& ports, int drop_percent)
    : table_("cairn_loss_" + std::to_string(getpid())) {
  if (geteuid() != 0) {
    why_not_ = "needs root for nftables";
    return;
  }
  if (!Run("command -v nft")) {
    why_not_ = "needs nftables (nft)";
    return;
  }
  std::string set;
  for (int p : ports) set += (set.empty() ? "" : ", ") + std::to_string(p);
  const std::string drop = " numgen random mod 100 lt " + std::to_string(drop_percent) + " counter drop";
  Run("nft delete table inet " + table_);
  created_ = Run("nft add table inet " + table_);
  // Loopback packets pass the output hook once: dropping there loses them in either direction.
  if (!created_ ||
      !Run("nft 'add chain inet " + table_ + " out { type filter hook output priority 0; policy accept; }'") ||
      !Run("nft 'add rule inet " + table_ + " out tcp dport { " + set + " }" + drop + "'") ||
      !Run("nft 'add rule inet " + table_ + " out tcp sport { " + set + " }" + drop + "'")) {
    why_not_ = "nftables random drops are not available here";
  }
}

LoopbackLoss::~LoopbackLoss() {
  if (created_) Run("nft delete table inet " + table_);
}

uint64_t NftCountedPackets(const std::string& list_command) {
  uint64_t total = 0;
  FILE* pipe = popen((list_command + " 2>/dev/null").c_str(), "r");
  if (pipe == nullptr) return 0;
  char line[512];
  while (std::fgets(line, sizeof(line), pipe) != nullptr) {
    const char* packets = std::strstr(line, "packets ");
    if (packets != nullptr) total += std::strtoull(packets + 8, nullptr, 10);
  }
  pclose(pipe);
  return total;
}

uint64_t LoopbackLoss::Dropped() const { return NftCountedPackets("nft list table inet " + table_); }

}  // namespace cairn::testing
