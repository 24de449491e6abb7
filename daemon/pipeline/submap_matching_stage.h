#pragma once
// The robot's loop closures from submap matching (thesis 6.1): finished submaps get their
// features, the pairing ranks pairs by the graph's current estimates, the pool matches them, and
// each match goes to the graph as a factor c. The stage lives on the graph thread (it reads the
// graph's origins and adds factors); the expensive work runs on the matcher pool, a few
// low-priority threads with a bounded job queue, so nothing else waits for it. In deterministic
// replays every job runs inline when it is handed out, at fixed points of the graph's input, so a
// replay closes the same loops every time.
//
// Every attempt is remembered (one row of matches.csv), with the graph's verdict.

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "daemon/pipeline/executor.h"
#include "daemon/pipeline/graph_stage.h"
#include "daemon/pipeline/team_link.h"
#include "daemon/pipeline/latency_histogram.h"
#include "daemon/pipeline/submap_matching_options.h"
#include "mapping/matching/submap_feature_extractor.h"
#include "mapping/matching/submap_matcher.h"
#include "mapping/matching/submap_pairing.h"
#include "mapping/submap.h"

namespace cairn {

struct MatchAttempt {
  SubmapKey a, b;
  SubmapMatchResult result;
  bool accepted = false;  // the graph took the factor
  std::string verdict;    // why not, or "added"
};

struct SubmapMatchingReport {
  uint64_t submaps = 0;
  uint64_t suitable = 0;
  uint64_t searchable = 0;  // unsuitable for descriptors, kept for the grey-level search
  uint64_t attempts = 0;
  uint64_t matched = 0;
  uint64_t accepted = 0;   // factors the graph took
  uint64_t team_submaps = 0;   // of `submaps`, teammates'
  uint64_t team_attempts = 0;  // pairs teammates tried (not tried here)
  uint64_t jobs_waiting_max = 0;  // high water of the pool's queue
  double features_ms_p50 = 0.0, features_ms_max = 0.0;
  double match_ms_p50 = 0.0, match_ms_max = 0.0;
  uint64_t features_bytes = 0;  // what the kept features of every submap hold
  std::vector<std::string> errors;  // the first few, verbatim
  // Every pair of this robot's submaps at the end, by why it was or was not attempted.
  std::vector<std::pair<std::string, uint64_t>> pairs;
};

class SubmapMatchingStage {
 public:
  // `pool` schedules the workers (live only). `notify` is called from a worker when a result is
  // ready, so the graph thread wakes up.
  SubmapMatchingStage(const SubmapMatchingOptions& options, std::string robot, bool deterministic,
                      const ExecutorOptions& pool, std::function<void()> notify);
  ~SubmapMatchingStage();
  SubmapMatchingStage(const SubmapMatchingStage&) = delete;
  SubmapMatchingStage& operator=(const SubmapMatchingStage&) = delete;

  void Start();

  // Graph thread: a finished submap of this robot.
  void OnSubmap(std::shared_ptr<const Submap> submap);
  // Team mode: robots' names by graph letter, and where this robot's attempts and matches go.
  // Pairs of two robots are tried by one of them only (decided from the pair, so every robot
  // agrees without talking); teammates' attempts are never repeated.
  void SetTeam(std::map<char, std::string> names, TeamLink* team);
  // Graph thread: a teammate's finished submap (its origin's frame index in the graph).
  void OnTeamSubmap(const std::string& robot, uint64_t frame, std::shared_ptr<const Submap> submap);
  // Graph thread: a pair a teammate tried.
  void OnTeamAttempt(const TeamMatch& pair, bool matched);
  // Which robot of the team tries the pair (a robot's own pairs: itself).
  static std::string PairOwner(const SubmapKey& a, const SubmapKey& b);
  // Graph thread: takes the pool's results into the graph and hands out new pairs.
  void Step(GraphStage& graph);
  // End of the run (graph thread stopped): every pair matched, the pool stopped.
  void Drain(GraphStage& graph);
  // Nothing in flight after a Step(): no candidate pair is left either.
  bool Idle() const { return in_flight_ == 0; }

  const std::vector<MatchAttempt>& attempts() const { return attempts_; }
  SubmapMatchingReport report() const;
  std::vector<ExecutorReport> executor_reports() const;
  // matches.csv: one row per attempt.
  std::string FormatCsv() const;

 private:
  struct Job {
    bool features = false;  // else a match
    std::shared_ptr<const Submap> submap;
    SubmapKey key;          // of `submap`
    SubmapPair pair;
    std::shared_ptr<const SubmapFeatures> a, b;
  };
  struct Done {
    Job job;
    std::shared_ptr<const SubmapFeatures> features;
    SubmapMatchResult match;
  };
  Done Run(const Job& job) const;
  void Submit(Job job);
  void WorkerLoop(std::stop_token stop);
  void StopWorkers();  // lets the workers finish their job and joins them
  void Take(Done done, GraphStage& graph);
  void RefreshEstimates(GraphStage& graph);
  void Error(const std::string& what);

  SubmapMatchingOptions options_;
  std::string robot_;
  std::map<char, std::string> names_;   // team mode: graph letter -> robot name
  std::map<std::string, char> letters_;
  TeamLink* team_ = nullptr;
  bool deterministic_;
  std::function<void()> notify_;
  SubmapFeatureExtractor extractor_;
  SubmapMatcher matcher_;
  SubmapPairing pairing_;
  std::map<SubmapKey, std::shared_ptr<const SubmapFeatures>> features_;
  std::vector<MatchAttempt> attempts_;
  size_t in_flight_ = 0;  // graph thread
  bool estimates_stale_ = true;

  std::vector<std::unique_ptr<Executor>> workers_;
  mutable std::mutex mutex_;
  std::condition_variable jobs_ready_;
  std::condition_variable results_ready_;
  std::deque<Job> jobs_;
  std::vector<Done> done_;
  bool stopping_ = false;

  LatencyHistogram features_time_, match_time_;
  SubmapMatchingReport report_;
};

}  // namespace cairn
