#pragma once
// Line association as it was before LineAssociator bounded the distances: the distance of every
// pairing of eligible edges, then the same selection. The reference the bounded association is
// checked and timed against (LineAssociatorTest, cairn bench landmarks).

#include <vector>

#include "mapping/matching/line_associator.h"
#include "mapping/matching/unambiguous_pairs.h"

namespace cairn::testing {

inline std::vector<LineAssociation> EveryLinePairing(
    const LineAssociator& associator, const LineAssociationOptions& options, const std::vector<SubmapLine>& a,
    const SubmapPlacement& pa, const std::vector<SubmapLine>& b, const SubmapPlacement& pb) {
  std::vector<LineAssociation> candidates;
  for (size_t i = 0; i < a.size(); ++i) {
    if (!associator.Eligible(a[i])) continue;
    for (size_t j = 0; j < b.size(); ++j) {
      if (!associator.Eligible(b[j])) continue;
      candidates.push_back(
          LineAssociation{static_cast<int>(i), static_cast<int>(j), associator.Distance(a[i], pa, b[j], pb)});
    }
  }
  return UnambiguousPairs(candidates, options.gate_chi2, options.ambiguity_chi2);
}

}  // namespace cairn::testing
