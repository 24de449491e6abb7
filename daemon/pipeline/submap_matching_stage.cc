#include "daemon/pipeline/submap_matching_stage.h"

#include <cmath>
#include <cstdio>
#include <utility>

#include "common/bounded_errors.h"

namespace cairn {
namespace {

std::string Key(const SubmapKey& k) { return k.robot + "/" + std::to_string(k.id); }

// The CSV field as written: commas and quotes would break the row.
std::string Field(std::string s) {
  for (char& c : s) {
    if (c == ',' || c == '"' || c == '\n') c = ';';
  }
  return s;
}

}  // namespace

SubmapMatchingStage::SubmapMatchingStage(const SubmapMatchingOptions& options, std::string robot,
                                         bool deterministic, const ExecutorOptions& pool,
                                         std::function<void()> notify)
    : options_(options),
      robot_(std::move(robot)),
      deterministic_(deterministic),
      notify_(std::move(notify)),
      extractor_(options.features, options.dof),
      matcher_(options.matcher),
      pairing_(options.pairing) {
  if (!deterministic_) {
    for (int64_t i = 0; i < options_.workers; ++i)
      workers_.push_back(std::make_unique<Executor>("matcher-" + std::to_string(i), pool));
  }
}

SubmapMatchingStage::~SubmapMatchingStage() { StopWorkers(); }

void SubmapMatchingStage::StopWorkers() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  jobs_ready_.notify_all();
  for (auto& w : workers_) {
    w->RequestStop();
    w->Join();
  }
}

void SubmapMatchingStage::Start() {
  for (auto& w : workers_) w->Start([this](std::stop_token stop) { WorkerLoop(stop); });
}

void SubmapMatchingStage::Error(const std::string& what) {
  AppendBoundedError(report_.errors, what);
}

SubmapMatchingStage::Done SubmapMatchingStage::Run(const Job& job) const {
  Done done;
  done.job = job;
  if (job.features) {
    done.features = std::make_shared<const SubmapFeatures>(extractor_.Extract(*job.submap));
  } else {
    done.match = job.pair.has_prior ? matcher_.Match(*job.a, *job.b, job.pair.prior) : matcher_.Match(*job.a, *job.b);
  }
  return done;
}

void SubmapMatchingStage::WorkerLoop(std::stop_token stop) {
  while (true) {
    Job job;
    {
      std::unique_lock lock(mutex_);
      jobs_ready_.wait(lock, [&] { return stopping_ || stop.stop_requested() || !jobs_.empty(); });
      if (jobs_.empty()) return;  // stopping, nothing left
      job = std::move(jobs_.front());
      jobs_.pop_front();
    }
    Done done = Run(job);
    {
      std::lock_guard lock(mutex_);
      done_.push_back(std::move(done));
    }
    results_ready_.notify_all();
    if (notify_) notify_();
  }
}

void SubmapMatchingStage::Submit(Job job) {
  ++in_flight_;
  if (deterministic_ || workers_.empty()) {
    Done done = Run(job);
    std::lock_guard lock(mutex_);
    done_.push_back(std::move(done));
    return;
  }
  {
    std::lock_guard lock(mutex_);
    jobs_.push_back(std::move(job));
    report_.jobs_waiting_max = std::max<uint64_t>(report_.jobs_waiting_max, jobs_.size());
  }
  jobs_ready_.notify_one();
}

void SubmapMatchingStage::OnSubmap(std::shared_ptr<const Submap> submap) {
  if (submap == nullptr) return;
  const uint64_t id = submap->metadata().id;
  OnTeamSubmap(robot_, id, std::move(submap));
}

void SubmapMatchingStage::OnTeamSubmap(const std::string& robot, uint64_t frame, std::shared_ptr<const Submap> submap) {
  if (submap == nullptr) return;
  ++report_.submaps;
  if (robot != robot_) ++report_.team_submaps;
  Job job;
  job.features = true;
  job.submap = std::move(submap);
  job.key = SubmapKey{robot, frame};
  Submit(std::move(job));
}

std::string SubmapMatchingStage::PairOwner(const SubmapKey& a, const SubmapKey& b) {
  if (a.robot == b.robot) return a.robot;
  // FNV-1a of the ordered pair: the same answer on every robot, and about half the pairs each.
  const auto& [first, second] = a < b ? std::pair(a, b) : std::pair(b, a);
  uint64_t h = 1469598103934665603ull;
  for (const std::string& part : {first.robot, std::to_string(first.id), second.robot, std::to_string(second.id)}) {
    for (unsigned char c : part) h = (h ^ c) * 1099511628211ull;
    h = (h ^ 0xff) * 1099511628211ull;
  }
  return (h >> 17) % 2 == 0 ? first.robot : second.robot;
}

void SubmapMatchingStage::SetTeam(std::map<char, std::string> names, TeamLink* team) {
  names_ = std::move(names);
  for (const auto& [letter, name] : names_) letters_[name] = letter;
  team_ = team;
  pairing_.SetOwnership([robot = robot_](const SubmapKey& a, const SubmapKey& b) { return PairOwner(a, b) == robot; });
}

void SubmapMatchingStage::OnTeamAttempt(const TeamMatch& pair, bool matched) {
  const SubmapKey a{pair.robot_a, pair.frame_a}, b{pair.robot_b, pair.frame_b};
  if (pairing_.Attempted(a, b) && pairing_.Outcome(a, b).has_value()) return;
  pairing_.MarkAttempted(a, b, matched ? MatchStatus::kMatched : MatchStatus::kNoMatch);
  ++report_.team_attempts;
}

void SubmapMatchingStage::RefreshEstimates(GraphStage& graph) {
  const std::vector<OriginEstimate> origins = graph.OriginEstimates(/*covariances=*/true);
  for (const OriginEstimate& o : origins) {
    std::string robot = robot_;
    if (o.robot != graph.robot()) {
      const auto name = names_.find(o.robot);
      if (name == names_.end()) continue;
      robot = name->second;
    }
    const auto f = features_.find(SubmapKey{robot, o.frame_id});
    if (f == features_.end()) continue;
    PairingSubmap p;
    p.key = f->first;
    p.matchable = f->second->matchable();
    p.box_xy = f->second->match_box_xy();
    p.placed = o.has_covariance;
    // Robots not tied to this one each float on their own (two of them may be tied to each other;
    // the pairing then tries a global search where a prior would do, never the reverse).
    p.component = o.connected ? 0 : 1 + static_cast<unsigned char>(o.robot);
    p.T_world_submap = o.T_global_origin;
    p.covariance = o.covariance;
    p.robot_ties = graph.OutsideTies(o.robot);
    pairing_.Update(p);
  }
  estimates_stale_ = false;
}

void SubmapMatchingStage::Take(Done done, GraphStage& graph) {
  --in_flight_;
  if (done.job.features) {
    const SubmapFeatures& f = *done.features;
    features_time_.Record(Duration::Seconds((f.keypoint_ms + f.descriptor_ms) * 1e-3));
    if (f.suitable()) ++report_.suitable;
    if (f.searchable) ++report_.searchable;
    features_[done.job.key] = done.features;
    estimates_stale_ = true;
    return;
  }
  const SubmapPair& pair = done.job.pair;
  MatchAttempt attempt{pair.a, pair.b, std::move(done.match), false, ""};
  ++report_.attempts;
  match_time_.Record(Duration::Seconds(attempt.result.times.total_ms * 1e-3));
  pairing_.MarkAttempted(pair.a, pair.b, attempt.result.status);
  if (attempt.result.matched()) {
    ++report_.matched;
    const char letter_a = pair.a.robot == robot_ ? graph.robot() : letters_.count(pair.a.robot) ? letters_.at(pair.a.robot) : 0;
    const char letter_b = pair.b.robot == robot_ ? graph.robot() : letters_.count(pair.b.robot) ? letters_.at(pair.b.robot) : 0;
    bool held = false;
    const Status s = graph.AddMatch(letter_a, pair.a.id, letter_b, pair.b.id, attempt.result.T_a_b,
                                    attempt.result.covariance, options_.tilt_sigma, &held);
    attempt.accepted = s.ok();
    attempt.verdict = !s.ok() ? s.ToString() : held ? "to the team screen" : "added";
    if (s.ok()) {
      ++report_.accepted;
      estimates_stale_ = true;
    } else {
      Error("match " + Key(pair.a) + " - " + Key(pair.b) + ": " + s.ToString());
    }
  } else {
    attempt.verdict = "not matched";
  }
  if (team_ != nullptr) {
    TeamMatch m;
    m.robot_a = pair.a.robot;
    m.frame_a = pair.a.id;
    m.robot_b = pair.b.robot;
    m.frame_b = pair.b.id;
    if (attempt.accepted) {
      m.T_a_b = attempt.result.T_a_b;
      m.covariance = attempt.result.covariance;
      m.tilt_sigma = options_.tilt_sigma;
      team_->PublishMatch(m);
    }
    team_->PublishAttempt(m, attempt.result.matched(), attempt.verdict);
  }
  attempts_.push_back(std::move(attempt));
}

void SubmapMatchingStage::Step(GraphStage& graph) {
  const bool inline_jobs = deterministic_ || workers_.empty();
  while (true) {
    std::vector<Done> done;
    {
      std::lock_guard lock(mutex_);
      done.swap(done_);
    }
    for (Done& d : done) Take(std::move(d), graph);
    if (estimates_stale_) RefreshEstimates(graph);
    while (in_flight_ < static_cast<size_t>(options_.queue)) {
      std::optional<SubmapPair> pair = pairing_.Next();
      if (!pair) break;
      Job job;
      job.pair = std::move(*pair);
      job.a = features_.at(job.pair.a);
      job.b = features_.at(job.pair.b);
      Submit(std::move(job));
    }
    if (!inline_jobs) return;
    // Inline jobs are done already: take them, and the pairs their results unlock, now.
    std::lock_guard lock(mutex_);
    if (done_.empty()) return;
  }
}

void SubmapMatchingStage::Drain(GraphStage& graph) {
  while (true) {
    Step(graph);
    // Step hands out every candidate there is while the queue has room: nothing in flight means
    // nothing left to match.
    if (in_flight_ == 0) break;
    std::unique_lock lock(mutex_);
    results_ready_.wait_for(lock, std::chrono::milliseconds(50), [&] { return !done_.empty(); });
  }
  StopWorkers();
}

SubmapMatchingReport SubmapMatchingStage::report() const {
  SubmapMatchingReport r = report_;
  r.features_ms_p50 = features_time_.Quantile(0.5).seconds() * 1e3;
  r.features_ms_max = features_time_.max().seconds() * 1e3;
  r.match_ms_p50 = match_time_.Quantile(0.5).seconds() * 1e3;
  r.match_ms_max = match_time_.max().seconds() * 1e3;
  for (const auto& [key, f] : features_) r.features_bytes += f->memory_bytes();
  for (const auto& [skip, count] : pairing_.Census())
    r.pairs.emplace_back(std::string(skip == PairSkip::kNone ? "not yet attempted" : PairSkipName(skip)), count);
  return r;
}

std::vector<ExecutorReport> SubmapMatchingStage::executor_reports() const {
  std::vector<ExecutorReport> out;
  for (const auto& w : workers_) out.push_back(w->report());
  return out;
}

std::string SubmapMatchingStage::FormatCsv() const {
  std::string out =
      "robot_a,submap_a,robot_b,submap_b,status,x,y,z,yaw,cov_xx,cov_xy,cov_xz,cov_xyaw,cov_yy,cov_yz,cov_yyaw,"
      "cov_zz,cov_zyaw,cov_yawyaw,accepted,reason\n";
  char buffer[512];
  for (const MatchAttempt& a : attempts_) {
    const SubmapMatchResult& r = a.result;
    out += Field(a.a.robot) + "," + std::to_string(a.a.id) + "," + Field(a.b.robot) + "," + std::to_string(a.b.id) +
           "," + std::string(MatchStatusName(r.status));
    if (r.matched()) {
      std::snprintf(buffer, sizeof(buffer), ",%.6f,%.6f,%.6f,%.8f", r.T_a_b.x(), r.T_a_b.y(), r.T_a_b.z(),
                    r.T_a_b.yaw());
      out += buffer;
      for (int i = 0; i < 4; ++i) {
        for (int j = i; j < 4; ++j) {
          std::snprintf(buffer, sizeof(buffer), ",%.6e", r.covariance(i, j));
          out += buffer;
        }
      }
    } else {
      out += ",,,,,,,,,,,,,,";
    }
    out += std::string(",") + (a.accepted ? "true" : "false") + "," + Field(r.matched() ? a.verdict : r.reason) + "\n";
  }
  return out;
}

}  // namespace cairn
