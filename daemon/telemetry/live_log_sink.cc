#include "daemon/telemetry/live_log_sink.h"

#include <chrono>

#include "daemon/telemetry/foxglove_fields.h"
#include "foxglove/Log.pb.h"

namespace cairn {
namespace {

foxglove::Log::Level LevelOf(spdlog::level::level_enum level) {
  switch (level) {
    case spdlog::level::trace:
    case spdlog::level::debug: return foxglove::Log::DEBUG;
    case spdlog::level::info: return foxglove::Log::INFO;
    case spdlog::level::warn: return foxglove::Log::WARNING;
    case spdlog::level::err: return foxglove::Log::ERROR;
    case spdlog::level::critical: return foxglove::Log::FATAL;
    default: return foxglove::Log::UNKNOWN;
  }
}

}  // namespace

void LiveLogSink::Detach() {
  std::lock_guard lock(mutex_);
  publish_ = nullptr;
}

void LiveLogSink::sink_it_(const spdlog::details::log_msg& msg) {
  if (!publish_) return;
  const int64_t ns = std::chrono::duration_cast<std::chrono::nanoseconds>(msg.time.time_since_epoch()).count();
  foxglove::Log log;
  SetFoxgloveTime(Timestamp::FromNanoseconds(ns), log.mutable_timestamp());
  log.set_level(LevelOf(msg.level));
  log.set_message(std::string(msg.payload.data(), msg.payload.size()));
  log.set_name(name_);
  if (msg.source.filename != nullptr) log.set_file(msg.source.filename);
  log.set_line(static_cast<uint32_t>(std::max(0, msg.source.line)));
  encoded_.clear();
  log.SerializeToString(&encoded_);
  publish_(Timestamp::FromNanoseconds(ns),
           {reinterpret_cast<const uint8_t*>(encoded_.data()), encoded_.size()});
}

}  // namespace cairn
