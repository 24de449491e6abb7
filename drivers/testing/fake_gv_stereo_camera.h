#pragma once
// Two GigE Vision cameras for the Aravis driver's tests: Aravis' own fake camera (ArvGvFakeCamera,
// GVCP and GVSP over UDP), twice. Each binds the GVCP port 3956 on one address, so each gets a
// loopback address of its own (127.0.0.x, added to `lo` when missing, which needs CAP_NET_ADMIN,
// and removed again on destruction); the driver opens them by address, without broadcast
// discovery. Tests that run at the same time must use different addresses.
//
// The cameras serve the gray images a test function draws for each frame id, encoded in the pixel
// format the driver configured (Mono8 as is, Mono16 as value * 257, Bayer as the same value on
// every site). Either camera can be stopped (gone from the network, as a pulled cable) and
// started again, and made to drop a share of its stream packets.

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "common/status.h"

typedef struct _ArvGvFakeCamera ArvGvFakeCamera;
typedef struct _ArvBuffer ArvBuffer;

namespace cairn::testing {

class FakeGvStereoCamera {
 public:
  // Fills `gray` (width * height, rows packed) with camera `side`'s (0 left, 1 right) image of
  // frame `frame_id` taken at `timestamp_ns` (the frame's device time: the fake cameras' clock is
  // the host's realtime clock, and both take their frames on the same multiples of the frame
  // period). Called on the camera's own thread.
  using ImageFunction = std::function<void(int side, uint64_t frame_id, int64_t timestamp_ns, int width,
                                           int height, uint8_t* gray)>;

  // Starts both cameras on `left_address` and `right_address` (127.0.0.x). The error says why not
  // (no permission to add the addresses, the port taken).
  static Expected<std::unique_ptr<FakeGvStereoCamera>> Create(const std::string& left_address,
                                                              const std::string& right_address,
                                                              ImageFunction image);
  ~FakeGvStereoCamera();
  FakeGvStereoCamera(const FakeGvStereoCamera&) = delete;
  FakeGvStereoCamera& operator=(const FakeGvStereoCamera&) = delete;

  void StopCamera(int side);
  Status StartCamera(int side);
  // Share of GVSP packets (leader, data, trailer) camera `side` drops, in [0, 1].
  void SetPacketLoss(int side, double ratio);

  const std::string& address(int side) const { return heads_[side].address; }
  uint64_t frames_served(int side) const { return heads_[side].served.load(); }

 private:
  struct Head {
    FakeGvStereoCamera* owner = nullptr;
    int side = 0;
    std::string address;
    ArvGvFakeCamera* camera = nullptr;
    std::vector<uint8_t> gray;  // the fake camera's thread's scratch image
    std::atomic<uint64_t> served{0};
  };

  FakeGvStereoCamera() = default;
  static void Fill(ArvBuffer* buffer, void* head, uint32_t exposure_us, uint32_t gain, uint32_t pixel_format);

  ImageFunction image_;
  Head heads_[2];
  std::vector<std::string> added_addresses_;
};

}  // namespace cairn::testing
