#pragma once
// A per-link byte budget: tokens accrue at `rate` bytes/s up to `burst`. A message may go while the
// balance is positive and may overdraw it, so an item larger than the burst still goes and the
// mean rate holds; the debt delays what follows.

#include <cstddef>

#include "common/timestamp.h"

namespace cairn {

class TokenBucket {
 public:
  TokenBucket(double rate_bytes_per_s, double burst_bytes);

  bool Ready(Timestamp now);
  void Spend(Timestamp now, size_t bytes);
  // How long until Ready() (zero when ready now).
  Duration Wait(Timestamp now);
  double balance(Timestamp now);

 private:
  void Refill(Timestamp now);

  double rate_;
  double burst_;
  double balance_;
  Timestamp last_;
  bool started_ = false;
};

}  // namespace cairn
