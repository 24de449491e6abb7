#include "daemon/telemetry/protobuf_schema.h"

#include <set>

#include <google/protobuf/descriptor.pb.h>

namespace cairn {
namespace {

void AddFile(const google::protobuf::FileDescriptor* file, std::set<std::string>* seen,
             google::protobuf::FileDescriptorSet* set) {
  if (!seen->insert(file->name()).second) return;
  // Dependencies first, as protoc orders them.
  for (int i = 0; i < file->dependency_count(); ++i) AddFile(file->dependency(i), seen, set);
  file->CopyTo(set->add_file());
}

}  // namespace

std::string ProtobufFileDescriptorSet(const google::protobuf::Descriptor* descriptor) {
  google::protobuf::FileDescriptorSet set;
  std::set<std::string> seen;
  AddFile(descriptor->file(), &seen, &set);
  return set.SerializeAsString();
}

}  // namespace cairn
