#pragma once
// An spdlog sink that hands every log line to the live stream as foxglove.Log (Foxglove's Log
// panel). Lines come from any thread; they are encoded under the sink's lock and published,
// never waited on. Detach() stops the forwarding before the stream goes away.

#include <functional>
#include <mutex>
#include <span>
#include <string>

#include <spdlog/sinks/base_sink.h>

#include "common/timestamp.h"

namespace cairn {

class LiveLogSink final : public spdlog::sinks::base_sink<std::mutex> {
 public:
  using Publish = std::function<void(Timestamp wall_time, std::span<const uint8_t> encoded)>;
  LiveLogSink(std::string name, Publish publish) : name_(std::move(name)), publish_(std::move(publish)) {}

  void Detach();

 protected:
  void sink_it_(const spdlog::details::log_msg& msg) override;
  void flush_() override {}

 private:
  std::string name_;
  Publish publish_;
  std::string encoded_;
};

}  // namespace cairn
