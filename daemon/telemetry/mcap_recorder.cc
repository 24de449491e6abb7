#include "daemon/telemetry/mcap_recorder.h"

#include <cstdio>

#include "cairn/calibration.pb.h"
#include "daemon/telemetry/protobuf_schema.h"

namespace cairn {

McapRecorder::McapRecorder(std::string directory, RecordingOptions options)
    : directory_(std::move(directory)), options_(options) {}

McapRecorder::~McapRecorder() { (void)Close(); }

Status McapRecorder::EnsureOpen(Timestamp time) {
  if (writer_.is_open()) return Status::Ok();
  char name[32];
  std::snprintf(name, sizeof(name), "recording-%03d.mcap", file_index_++);
  const std::string path = directory_ + "/" + name;
  McapWriterOptions o;
  o.compression = options_.compression;
  o.chunk_size = static_cast<size_t>(options_.chunk_size);
  o.library = "cairn";
  CAIRN_RETURN_IF_ERROR(writer_.Open(path, o));
  report_.files.push_back(path);
  // Every file is self-contained: schemas and channels again after each rotation.
  std::map<const google::protobuf::Descriptor*, uint16_t> schema_ids;
  // A protobuf channel; messages sharing a type share its schema record.
  const auto add_channel = [&](const char* topic, const google::protobuf::Descriptor* d) -> Expected<uint16_t> {
    if (schema_ids.count(d) == 0) {
      const std::string set = ProtobufFileDescriptorSet(d);
      auto id = writer_.AddSchema(d->full_name(), "protobuf",
                                  {reinterpret_cast<const uint8_t*>(set.data()), set.size()});
      if (!id.ok()) return id.status();
      schema_ids[d] = *id;
    }
    return writer_.AddChannel(topic, "protobuf", schema_ids[d]);
  };
  for (int t = 0; t < kTelemetryTopicCount; ++t) {
    const auto topic = static_cast<TelemetryTopic>(t);
    auto ch = add_channel(TelemetryTopicName(topic), TelemetryTopicDescriptor(topic));
    if (!ch.ok()) return ch.status();
    channel_[t] = *ch;
  }
  if (!calibration_.empty()) {
    auto ch = add_channel("/calibration", msg::Calibration::descriptor());
    if (!ch.ok()) return ch.status();
    const uint64_t ns = static_cast<uint64_t>(time.nanoseconds());
    CAIRN_RETURN_IF_ERROR(writer_.Write(*ch, 0, ns, ns, {reinterpret_cast<const uint8_t*>(calibration_.data()),
                                                        calibration_.size()}));
    ++report_.messages["/calibration"];
  }
  return Status::Ok();
}

Status McapRecorder::Write(TelemetryTopic topic, Timestamp time, const std::string& encoded) {
  const int t = static_cast<int>(topic);
  Status s = EnsureOpen(time);
  if (s.ok()) {
    const uint64_t ns = static_cast<uint64_t>(time.nanoseconds());
    s = writer_.Write(channel_[t], sequence_[t]++, ns, ns,
                      {reinterpret_cast<const uint8_t*>(encoded.data()), encoded.size()});
  }
  if (!s.ok()) {
    ++report_.write_errors;
    return s;
  }
  ++report_.messages[TelemetryTopicName(topic)];
  report_.bytes = bytes_closed_ + writer_.bytes_written();
  if (writer_.bytes_written() >= static_cast<uint64_t>(options_.rotate_size)) {
    CAIRN_RETURN_IF_ERROR(writer_.Close());
    bytes_closed_ += writer_.bytes_written();
    report_.bytes = bytes_closed_;
  }
  return Status::Ok();
}

Status McapRecorder::Close() {
  if (!writer_.is_open()) return Status::Ok();
  const Status s = writer_.Close();
  bytes_closed_ += writer_.bytes_written();
  report_.bytes = bytes_closed_;
  return s;
}

}  // namespace cairn
