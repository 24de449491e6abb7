#pragma once
// The stereo cameras' trigger on a GPIO line through libgpiod 1.6 (gpiod_trigger_options.h). The
// driver's thread opens the chip, requests edge events on the input line and, when configured,
// the output line, then sleeps in poll() on the line's event descriptor, a timer for the output
// pulses and an eventfd that Stop() and SetRate() write: it never spins, and Stop() returns as soon
// as the thread has seen the eventfd.
//
// Each edge becomes a TriggerEvent through SensorSink::OnTrigger: its time is the kernel's stamp of
// the interrupt (CLOCK_MONOTONIC since Linux 5.7, the clock every driver stamps with; an older
// kernel's CLOCK_REALTIME stamps are converted, trigger_edge_sequencer.h), its sequence a running
// count that also skips the edges the time gaps say were lost. Edges are read in batches into an
// array allocated at construction: nothing is allocated per edge.
//
// Pulses: with an output line and a rate, the line goes high at every period's start on an
// absolute timer (no drift) and low `pulse_width` later. A period the thread wakes too late for is
// skipped, not squeezed in, and counted.
//
// Faults, reported to the sink and never fatal: a chip that is not there or vanishes
// (kDisconnected: the chip is looked for again every `reopen_interval`, and edges resume), a line
// that does not exist or is held by another program (kOther, retried likewise), edges lost by the
// time gaps (kOverrun) and stamps the clocks cannot place (kCorruptSample), each at most once a
// second, and no edge for `timeout` while the line is open (kTimeout, once per silence).

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

#include <sys/types.h>

#include "common/monotonic_clock.h"
#include "drivers/fault_throttle.h"
#include "drivers/gpiod_trigger_options.h"
#include "drivers/trigger_edge_sequencer.h"
#include "hal/trigger_interface.h"

struct gpiod_chip;
struct gpiod_line;
struct gpiod_line_event;

namespace cairn {

struct GpiodTriggerCounts {
  uint64_t edges = 0;          // published
  uint64_t missed = 0;         // lost, by the time gaps at a known rate
  uint64_t corrupt = 0;        // stamps neither clock could place, or not after the previous edge
  uint64_t pulses = 0;         // emitted on the output line
  uint64_t skipped_pulses = 0;  // periods the thread woke too late for
  uint64_t timeouts = 0;
  uint64_t reconnections = 0;
  uint64_t open_attempts = 0;
};

class GpiodTrigger final : public TriggerInterface {
 public:
  explicit GpiodTrigger(GpiodTriggerOptions options);
  ~GpiodTrigger() override;

  // "gpiod:CHIP/LINE", the device name in faults.
  std::string name() const override;
  // Checks the options and starts the thread; a missing chip is a fault, not an error: the
  // thread keeps looking for it.
  Status Start(SensorSink* sink) override;
  void Stop() override;
  bool finished() const override { return false; }
  // The output's pulse rate and the edges' expected rate (0: no pulses, rate unknown); applied by
  // the thread at once, kept across reopenings.
  Status SetRate(double hz) override;

  // A snapshot for reports.
  GpiodTriggerCounts counts() const;

 private:
  Status Open();
  void Close();
  void Run(std::stop_token stop);
  // Sleeps until `wait` has passed or the eventfd is written.
  void Sleep(Duration wait);
  void Serve();
  void DrainWake();
  void ApplyRate(Timestamp now);
  void ReadEdges();
  void Pulse(Timestamp now);
  void ArmTimer(Timestamp at);
  void Watch(Timestamp now);
  // The open chip is gone: one fault, closed, looked for again after reopen_interval.
  void Lost(const std::string& why, Timestamp now);
  void Fault(DeviceFaultKind kind, const std::string& detail);

  const GpiodTriggerOptions options_;
  SensorSink* sink_ = nullptr;
  MonotonicClock clock_;
  int wake_fd_ = -1;  // eventfd; Stop() and SetRate() write it
  std::atomic<double> rate_hz_;

  // Owned by the thread while it runs.
  gpiod_chip* chip_ = nullptr;
  gpiod_line* input_ = nullptr;
  gpiod_line* output_ = nullptr;
  int event_fd_ = -1;  // the input line's, owned by libgpiod
  int timer_fd_ = -1;
  std::string chip_node_;  // /dev/gpiochipN, watched for the chip vanishing
  dev_t chip_device_ = 0;
  std::unique_ptr<gpiod_line_event[]> events_;
  TriggerEdgeSequencer sequencer_;
  double armed_rate_hz_ = -1.0;  // the rate the timer runs at; -1: not applied since opening
  bool pulse_high_ = false;
  Timestamp next_rise_;
  Timestamp last_open_, last_edge_, last_watch_;
  bool reported_ = false;   // the current outage was reported
  bool timed_out_ = false;
  bool realtime_noted_ = false;
  FaultThrottle missed_throttle_, corrupt_throttle_;

  std::atomic<uint64_t> edges_{0}, missed_{0}, corrupt_{0}, pulses_{0}, skipped_pulses_{0}, timeouts_{0},
      reconnections_{0}, open_attempts_{0};
  std::jthread thread_;
};

}  // namespace cairn
