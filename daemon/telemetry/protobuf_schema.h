#pragma once
// The schema data MCAP stores for a protobuf channel: a serialized FileDescriptorSet holding the
// message's file and everything it imports, so readers decode without the .proto files.

#include <string>

#include <google/protobuf/descriptor.h>

namespace cairn {

std::string ProtobufFileDescriptorSet(const google::protobuf::Descriptor* descriptor);

}  // namespace cairn
