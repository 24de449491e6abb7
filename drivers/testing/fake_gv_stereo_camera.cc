#include "drivers/testing/fake_gv_stereo_camera.h"

#include <arpa/inet.h>
#include <arv.h>
#include <ifaddrs.h>
#include <netinet/in.h>

#include <cstdlib>
#include <cstring>

namespace cairn::testing {
namespace {

bool HasAddress(const std::string& address) {
  ifaddrs* list = nullptr;
  if (getifaddrs(&list) != 0) return false;
  bool found = false;
  for (ifaddrs* a = list; a != nullptr && !found; a = a->ifa_next) {
    if (a->ifa_addr == nullptr || a->ifa_addr->sa_family != AF_INET) continue;
    char text[INET_ADDRSTRLEN] = {};
    inet_ntop(AF_INET, &reinterpret_cast<sockaddr_in*>(a->ifa_addr)->sin_addr, text, sizeof text);
    found = address == text;
  }
  freeifaddrs(list);
  return found;
}

}  // namespace

Expected<std::unique_ptr<FakeGvStereoCamera>> FakeGvStereoCamera::Create(const std::string& left_address,
                                                                         const std::string& right_address,
                                                                         ImageFunction image) {
  std::unique_ptr<FakeGvStereoCamera> f(new FakeGvStereoCamera());
  f->image_ = std::move(image);
  const std::string addresses[2] = {left_address, right_address};
  for (int side : {0, 1}) {
    Head& h = f->heads_[side];
    h.owner = f.get();
    h.side = side;
    h.address = addresses[side];
    if (h.address.rfind("127.", 0) != 0)
      return InvalidArgumentError(h.address + " is not a loopback address");
    if (!HasAddress(h.address)) {
      // getifaddrs() must list the address: the fake camera looks its interface up there.
      const std::string command = "ip addr add " + h.address + "/8 dev lo >/dev/null 2>&1";
      if (std::system(command.c_str()) != 0 || !HasAddress(h.address))
        return UnavailableError("cannot add " + h.address +
                                " to the loopback interface (needs root and iproute2)");
      f->added_addresses_.push_back(h.address);
    }
  }
  for (int side : {0, 1}) CAIRN_RETURN_IF_ERROR(f->StartCamera(side));
  return f;
}

FakeGvStereoCamera::~FakeGvStereoCamera() {
  for (int side : {0, 1}) StopCamera(side);
  for (const std::string& a : added_addresses_) {
    const std::string command = "ip addr del " + a + "/8 dev lo >/dev/null 2>&1";
    if (std::system(command.c_str()) != 0) {
      // Left behind: harmless, and the next run finds it present.
    }
  }
}

Status FakeGvStereoCamera::StartCamera(int side) {
  Head& h = heads_[side];
  if (h.camera != nullptr) return Status::Ok();
  const std::string serial = side == 0 ? "CAIRN-L" : "CAIRN-R";
  h.camera = arv_gv_fake_camera_new(h.address.c_str(), serial.c_str());
  if (h.camera == nullptr || !arv_gv_fake_camera_is_running(h.camera)) {
    if (h.camera != nullptr) g_object_unref(h.camera);
    h.camera = nullptr;
    return UnavailableError("the fake GigE Vision camera cannot listen on " + h.address +
                            ":3956 (taken by another test?)");
  }
  arv_fake_camera_set_fill_pattern(arv_gv_fake_camera_get_fake_camera(h.camera), &FakeGvStereoCamera::Fill,
                                   &h);
  return Status::Ok();
}

void FakeGvStereoCamera::StopCamera(int side) {
  Head& h = heads_[side];
  if (h.camera == nullptr) return;
  g_object_unref(h.camera);  // joins its thread, closes its sockets
  h.camera = nullptr;
}

void FakeGvStereoCamera::SetPacketLoss(int side, double ratio) {
  if (heads_[side].camera != nullptr) g_object_set(heads_[side].camera, "gvsp-lost-ratio", ratio, nullptr);
}

void FakeGvStereoCamera::Fill(ArvBuffer* buffer, void* head, uint32_t /*exposure_us*/, uint32_t /*gain*/,
                              uint32_t pixel_format) {
  Head& h = *static_cast<Head*>(head);
  const int width = arv_buffer_get_image_width(buffer);
  const int height = arv_buffer_get_image_height(buffer);
  // The fake camera hands its own buffer over for filling, having checked that it holds the
  // payload (the size arv_buffer_get_data reports is what was received, nothing yet).
  auto* data = static_cast<uint8_t*>(const_cast<void*>(arv_buffer_get_data(buffer, nullptr)));
  const size_t pixels = static_cast<size_t>(width) * static_cast<size_t>(height);
  const size_t bytes_per_pixel = pixel_format == ARV_PIXEL_FORMAT_MONO_16 ? 2 : 1;
  if (data == nullptr || width <= 0 || height <= 0) return;
  h.gray.resize(pixels);
  h.owner->image_(h.side, arv_buffer_get_frame_id(buffer),
                  static_cast<int64_t>(arv_buffer_get_timestamp(buffer)), width, height, h.gray.data());
  if (bytes_per_pixel == 2) {
    for (size_t i = 0; i < pixels; ++i) {
      data[2 * i] = h.gray[i];  // little endian: value * 257
      data[2 * i + 1] = h.gray[i];
    }
  } else {
    std::memcpy(data, h.gray.data(), pixels);
  }
  h.served.fetch_add(1);
}

}  // namespace cairn::testing
