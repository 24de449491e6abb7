#pragma once
// Scheduling of one executor (a thread or a pool): the single place where threads, priorities,
// CPU affinity and queue depths are declared is CairndOptions::executors and ::queues below, with
// the defaults every robot profile starts from in configs/.

#include <vector>

#include "common/options_visitor.h"

namespace cairn {

struct ExecutorOptions {
  // SCHED_FIFO at `priority` (1..99), with the process memory locked. Where the system does not
  // allow it the executor runs at normal priority and the daemon logs one warning.
  bool realtime = false;
  int64_t priority = 0;
  // Nice value for normal-policy executors (-20 most favoured .. 19 least).
  int64_t nice = 0;
  // CPUs the threads may run on; empty = any.
  std::vector<double> cpus;

  void Visit(OptionsVisitor& v) {
    v.Flag("realtime", realtime);
    v.Integer("priority", priority, 0, 99, "");
    v.Integer("nice", nice, -20, 19, "");
    v.Numbers("cpus", cpus, 0, 1024, 0, 1023, "cpu index");
  }
  Status Validate() const {
    if (realtime && priority < 1) return InvalidArgumentError("a realtime executor needs priority 1..99");
    for (double c : cpus) {
      if (c != static_cast<double>(static_cast<int>(c))) return InvalidArgumentError("cpus must be whole numbers");
    }
    return Status::Ok();
  }
};

struct ExecutorsOptions {
  ExecutorOptions estimation;  // the hard-real-time filter thread
  ExecutorOptions stereo;      // rectification, SGM, depth
  ExecutorOptions vo;          // keyframe stereo visual odometry
  // Dense stereo (FPGA or SGM CPU kernel, whose `stereo.sgm.threads` workers it starts) and local
  // mapping; apart from the stereo executor so the odometry never waits for dense matching.
  ExecutorOptions mapping;
  ExecutorOptions telemetry;   // recording and the live stream
  ExecutorOptions graph;       // the SLAM graph's online optimization (low priority)
  // The graph's full solves after loop closures, live only (replays solve inline, deterministic).
  ExecutorOptions graph_full_solve;
  // The submap matcher pool's workers (matching.workers of them), the lowest priority.
  ExecutorOptions matcher;
  // The team exchange: the item store, ZeroMQ sockets and submap encoding (team.enabled).
  ExecutorOptions comms;
  // AprilTag detection of teammates and landmarks on the left rectified image (detection.enabled).
  ExecutorOptions detection;

  void Visit(OptionsVisitor& v) {
    v.Section("estimation", estimation);
    v.Section("stereo", stereo);
    v.Section("vo", vo);
    v.Section("mapping", mapping);
    v.Section("telemetry", telemetry);
    v.Section("graph", graph);
    v.Section("graph_full_solve", graph_full_solve);
    v.Section("matcher", matcher);
    v.Section("comms", comms);
    v.Section("detection", detection);
  }
};

// Bounded queues between stages. What a full queue drops is counted and reported.
struct QueueOptions {
  int64_t imu = 2048;
  int64_t wheel_odometry = 512;
  int64_t stereo = 4;
  // Rectified pairs waiting for the visual odometry.
  int64_t vo = 4;
  // Rectified pairs waiting for dense stereo and mapping.
  int64_t dense = 2;
  // Samples waiting for the telemetry executor (recording, live stream); IMU gets 8x this.
  int64_t telemetry = 64;
  // Filter estimates and frame switches waiting for the graph (about 400 s of frames at 10 Hz).
  int64_t graph = 4096;
  // Finished submaps waiting for the matcher.
  int64_t submaps = 64;
  // Rectified pairs waiting for tag detection, and its sightings waiting for the graph.
  int64_t detection = 2;
  int64_t sightings = 256;

  void Visit(OptionsVisitor& v) {
    v.Integer("imu", imu, 2, 1 << 20, "samples");
    v.Integer("wheel_odometry", wheel_odometry, 2, 1 << 20, "samples");
    v.Integer("stereo", stereo, 2, 1024, "frames");
    v.Integer("vo", vo, 2, 1024, "frames");
    v.Integer("dense", dense, 2, 1024, "frames");
    v.Integer("telemetry", telemetry, 2, 1 << 20, "samples");
    v.Integer("graph", graph, 2, 1 << 20, "items");
    v.Integer("submaps", submaps, 2, 1 << 16, "submaps");
    v.Integer("detection", detection, 2, 1024, "frames");
    v.Integer("sightings", sightings, 2, 1 << 20, "sightings");
  }
};

}  // namespace cairn
