#pragma once
// The selection shared by the landmark associators (planes, lines): of the candidate pairings
// {a, b, chi2} of two submaps' landmarks, keep those inside the gate that no rival pairing of
// either landmark comes within `ambiguity_chi2` of; so each landmark is paired at most once.

#include <algorithm>
#include <vector>

namespace cairn {

// `Pairing` has int members a and b and a double chi2 (negative: no pairing at all). The result is
// sorted by (a, b).
template <class Pairing>
std::vector<Pairing> UnambiguousPairs(const std::vector<Pairing>& candidates, double gate_chi2,
                                      double ambiguity_chi2) {
  // Rivals are counted up to the gate plus the margin, so a pairing just inside the gate is not
  // taken while a slightly worse rival lies just outside it.
  std::vector<Pairing> gated;
  for (const Pairing& p : candidates) {
    if (p.chi2 >= 0.0 && p.chi2 <= gate_chi2 + ambiguity_chi2) gated.push_back(p);
  }
  std::vector<Pairing> out;
  for (const Pairing& p : gated) {
    if (p.chi2 > gate_chi2) continue;
    const bool ambiguous = std::any_of(gated.begin(), gated.end(), [&](const Pairing& q) {
      return (q.a == p.a) != (q.b == p.b) && q.chi2 < p.chi2 + ambiguity_chi2;
    });
    if (!ambiguous) out.push_back(p);
  }
  std::sort(out.begin(), out.end(),
            [](const Pairing& x, const Pairing& y) { return x.a != y.a ? x.a < y.a : x.b < y.b; });
  return out;
}

}  // namespace cairn
