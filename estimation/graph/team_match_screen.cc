#include "estimation/graph/team_match_screen.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <Eigen/Cholesky>

#include "estimation/graph/max_clique.h"
#include "estimation/graph/pairwise_consistency.h"
#include "estimation/math/so3.h"

namespace cairn {
namespace {

Matrix6d CovarianceOf(const Matrix6d& information) {
  const Matrix6d c = information.ldlt().solve(Matrix6d::Identity());
  return 0.5 * (c + c.transpose());
}

double LogDeterminant(const Matrix6d& covariance) {
  const Eigen::LDLT<Matrix6d> ldlt(covariance);
  return ldlt.vectorD().array().abs().log().sum();
}

// The match with its lower robot letter first.
std::pair<char, char> PairOf(const SlamFactor& f) {
  const char a = RobotOfVariable(f.a), b = RobotOfVariable(f.b);
  return {std::min(a, b), std::max(a, b)};
}

std::string Name(uint64_t key) {
  return std::string(1, RobotOfVariable(key)) + "/" + std::to_string(IndexOfVariable(key));
}

std::string Name(const SlamFactor& f) { return Name(f.a) + " - " + Name(f.b); }

}  // namespace

// (T Exp(d)) Z = T Z Exp(Ad(Z^-1) d).
TeamMatchScreen::Relative TeamMatchScreen::Compose(const Relative& a, const Relative& b) {
  const Matrix6d A = Adjoint(b.T.Inverse());
  return Relative{a.T * b.T, A * a.covariance * A.transpose() + b.covariance};
}

// (Z Exp(d))^-1 = Z^-1 Exp(-Ad(Z) d).
TeamMatchScreen::Relative TeamMatchScreen::Invert(const Relative& a) {
  const Matrix6d A = Adjoint(a.T);
  return Relative{a.T.Inverse(), A * a.covariance * A.transpose()};
}

namespace {}  // namespace

TeamMatchScreen::TeamMatchScreen(const TeamMatchScreenOptions& options) : options_(options) {}

void TeamMatchScreen::AddFrameSwitch(const SlamFactor& w) {
  switches_[w.a] = {w.b, Relative{w.z, CovarianceOf(w.information)}};
}

void TeamMatchScreen::Offer(const SlamFactor& match, Timestamp now) {
  pairs_[PairOf(match)].held.push_back(Held{match, now, now != Timestamp()});
}

size_t TeamMatchScreen::held() const {
  size_t n = 0;
  for (const auto& [robots, pair] : pairs_) n += pair.held.size();
  return n;
}

std::optional<TeamMatchScreen::Relative> TeamMatchScreen::Segment(uint64_t from, uint64_t to) const {
  if (IndexOfVariable(to) < IndexOfVariable(from)) {
    const std::optional<Relative> back = Segment(to, from);
    if (!back) return std::nullopt;
    return Invert(*back);
  }
  Relative r;
  for (uint64_t at = from; at != to;) {
    const auto link = switches_.find(at);
    if (link == switches_.end() || IndexOfVariable(link->second.first) > IndexOfVariable(to))
      return std::nullopt;
    r = Compose(r, link->second.second);
    at = link->second.first;
  }
  return r;
}

std::optional<double> TeamMatchScreen::CycleChi2(const SlamFactor& first, const SlamFactor& second) const {
  // Both oriented from the lower robot letter (x) to the higher (y).
  auto oriented = [](const SlamFactor& f) {
    const Relative m{f.z, CovarianceOf(f.information)};
    if (RobotOfVariable(f.a) <= RobotOfVariable(f.b)) return std::make_tuple(f.a, f.b, m);
    return std::make_tuple(f.b, f.a, Invert(m));
  };
  const auto [xi, yi, mi] = oriented(first);
  const auto [xj, yj, mj] = oriented(second);
  if (RobotOfVariable(xi) != RobotOfVariable(xj) || RobotOfVariable(yi) != RobotOfVariable(yj))
    return std::nullopt;
  const std::optional<Relative> along_y = Segment(yi, yj), along_x = Segment(xj, xi);
  if (!along_y || !along_x) return std::nullopt;
  // x_i -> y_i -> y_j -> x_j -> x_i, every piece's perturbation carried to the cycle's end.
  const Relative cycle = Compose(Compose(Compose(mi, *along_y), Invert(mj)), *along_x);
  Vector6d e;
  e.head<3>() = cycle.T.t;
  e.tail<3>() = so3::Log(cycle.T.q);
  const Eigen::LDLT<Matrix6d> ldlt(cycle.covariance);
  if (ldlt.info() != Eigen::Success) return std::nullopt;
  return e.dot(ldlt.solve(e));
}

std::vector<ScreenedMatch> TeamMatchScreen::Decide(Timestamp now, bool final) {
  std::vector<ScreenedMatch> out;
  for (auto& [robots, pair] : pairs_) {
    if (pair.held.empty()) continue;
    for (Held& h : pair.held) {
      if (!h.stamped && now != Timestamp()) h = Held{h.factor, now, true};
    }
    if (pair.accepted.empty()) DecideHeld(pair, now, final, out);
    if (!pair.accepted.empty()) TestAgainstAccepted(pair, out);
  }
  return out;
}

void TeamMatchScreen::DecideHeld(Pair& pair, Timestamp now, bool final,
                                 std::vector<ScreenedMatch>& out) const {
  const size_t n = pair.held.size();
  std::vector<size_t> chosen;
  if (n >= 2) {
    const double pair_confidence = std::pow(options_.confidence, 1.0 / static_cast<double>(n - 1));
    const double threshold = ChiSquareQuantile(pair_confidence, 6);
    BitRows agree = MakeBitRows(n);
    for (size_t i = 0; i < n; ++i) {
      for (size_t j = i + 1; j < n; ++j) {
        const std::optional<double> chi2 = CycleChi2(pair.held[i].factor, pair.held[j].factor);
        if (chi2 && *chi2 <= threshold) SetEdge(agree, i, j);
      }
    }
    const CliqueResult clique = MaximumClique(agree);
    if (clique.members.size() >= 2)
      for (int m : clique.members) chosen.push_back(static_cast<size_t>(m));
  }
  if (chosen.empty()) {
    bool waited = final;
    for (const Held& h : pair.held)
      waited = waited || (h.stamped && now - h.received >= Duration::Seconds(options_.hold_seconds));
    if (!waited) return;
    // No second opinion came: the best determined match stands, the others are tested against it.
    size_t best = 0;
    double best_log_det = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < n; ++i) {
      const double d = LogDeterminant(CovarianceOf(pair.held[i].factor.information));
      if (d < best_log_det) {
        best_log_det = d;
        best = i;
      }
    }
    chosen.push_back(best);
  }
  std::vector<Held> rest;
  for (size_t i = 0; i < n; ++i) {
    if (std::find(chosen.begin(), chosen.end(), i) != chosen.end()) {
      pair.accepted.push_back(pair.held[i].factor);
      out.push_back(ScreenedMatch{pair.held[i].factor, true, ""});
    } else {
      rest.push_back(pair.held[i]);
    }
  }
  pair.held = std::move(rest);
}

void TeamMatchScreen::TestAgainstAccepted(Pair& pair, std::vector<ScreenedMatch>& out) const {
  for (const Held& h : pair.held) {
    const double pair_confidence =
        std::pow(options_.confidence, 1.0 / static_cast<double>(pair.accepted.size()));
    const double threshold = ChiSquareQuantile(pair_confidence, 6);
    std::string reason;
    for (const SlamFactor& a : pair.accepted) {
      const std::optional<double> chi2 = CycleChi2(h.factor, a);
      if (chi2 && *chi2 > threshold) {
        char numbers[96];
        std::snprintf(numbers, sizeof(numbers), ": cycle chi2 %.1f above %.1f", *chi2, threshold);
        reason = "match " + Name(h.factor) + " disagrees with the accepted match " + Name(a) + numbers;
        break;
      }
    }
    if (reason.empty()) pair.accepted.push_back(h.factor);
    out.push_back(ScreenedMatch{h.factor, reason.empty(), reason});
  }
  pair.held.clear();
}

}  // namespace cairn
