#include "daemon/comms/zmq_transport.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>

#include <zmq.h>

namespace cairn {
namespace {

constexpr const char* kZapEndpoint = "inproc://zeromq.zap.01";
constexpr const char* kZapDomain = "cairn";

std::string ZmqError() { return zmq_strerror(zmq_errno()); }

int Milliseconds(double seconds) { return static_cast<int>(std::lround(seconds * 1000.0)); }

Status SetInt(void* socket, int option, int value, const char* what) {
  if (zmq_setsockopt(socket, option, &value, sizeof(value)) != 0) {
    return InternalError(std::string("zmq_setsockopt ") + what + ": " + ZmqError());
  }
  return Status::Ok();
}

Status SetBytes(void* socket, int option, const std::string& value, const char* what) {
  if (zmq_setsockopt(socket, option, value.data(), value.size()) != 0) {
    return InternalError(std::string("zmq_setsockopt ") + what + ": " + ZmqError());
  }
  return Status::Ok();
}

// Options every socket of the team shares: a silent link is noticed and dropped, closing never
// waits for unsent messages (the exchange sends them again).
Status SetLinkOptions(void* socket, const ZmqTransportOptions& o) {
  CAIRN_RETURN_IF_ERROR(SetInt(socket, ZMQ_LINGER, 0, "ZMQ_LINGER"));
  CAIRN_RETURN_IF_ERROR(SetInt(socket, ZMQ_HEARTBEAT_IVL, Milliseconds(o.heartbeat_interval), "ZMQ_HEARTBEAT_IVL"));
  CAIRN_RETURN_IF_ERROR(
      SetInt(socket, ZMQ_HEARTBEAT_TIMEOUT, Milliseconds(o.heartbeat_timeout), "ZMQ_HEARTBEAT_TIMEOUT"));
  CAIRN_RETURN_IF_ERROR(SetInt(socket, ZMQ_HEARTBEAT_TTL, Milliseconds(o.heartbeat_timeout), "ZMQ_HEARTBEAT_TTL"));
  return Status::Ok();
}

// Receives the rest of a multipart message and drops it.
void Drain(void* socket) {
  int more = 0;
  size_t size = sizeof(more);
  while (zmq_getsockopt(socket, ZMQ_RCVMORE, &more, &size) == 0 && more != 0) {
    zmq_msg_t part;
    zmq_msg_init(&part);
    const int n = zmq_msg_recv(&part, socket, ZMQ_DONTWAIT);
    zmq_msg_close(&part);
    if (n < 0) break;
  }
}

}  // namespace

Expected<std::unique_ptr<ZmqTransport>> ZmqTransport::Create(const ZmqTransportOptions& options,
                                                             const CurveKeyPair& keys,
                                                             const std::vector<ZmqPeer>& peers) {
  std::unique_ptr<ZmqTransport> t(new ZmqTransport());
  if (Status s = t->Open(options, keys, peers); !s.ok()) return s;
  return t;
}

Status ZmqTransport::Open(const ZmqTransportOptions& options, const CurveKeyPair& keys,
                          const std::vector<ZmqPeer>& peers) {
  if (!zmq_has("curve")) return UnavailableError("this libzmq has no CURVE security (built without libsodium)");
  const std::string public_key = CurveKeys::Decode(keys.public_key);
  const std::string secret_key = CurveKeys::Decode(keys.secret_key);
  if (public_key.empty() || secret_key.empty()) return InvalidArgumentError("this robot's CURVE keys are not valid Z85");
  for (const ZmqPeer& p : peers) {
    const std::string key = CurveKeys::Decode(p.public_key);
    if (key.empty()) return InvalidArgumentError("peer '" + p.name + "': public key is not a Z85 CURVE key");
    if (key == public_key) return InvalidArgumentError("peer '" + p.name + "' has this robot's own public key");
    if (!names_by_key_.emplace(key, p.name).second) {
      return InvalidArgumentError("peer '" + p.name + "' shares its public key with '" + names_by_key_[key] + "'");
    }
  }
  context_ = zmq_ctx_new();
  if (context_ == nullptr) return InternalError("zmq_ctx_new: " + ZmqError());

  // The ZAP handler must be bound before the server socket asks it anything.
  zap_ = zmq_socket(context_, ZMQ_REP);
  if (zap_ == nullptr) return InternalError("zmq_socket (ZAP): " + ZmqError());
  CAIRN_RETURN_IF_ERROR(SetInt(zap_, ZMQ_LINGER, 0, "ZMQ_LINGER"));
  if (zmq_bind(zap_, kZapEndpoint) != 0) return InternalError(std::string("bind ") + kZapEndpoint + ": " + ZmqError());
  zap_thread_ = std::thread([this] { ServeZap(); });

  router_ = zmq_socket(context_, ZMQ_ROUTER);
  if (router_ == nullptr) return InternalError("zmq_socket (ROUTER): " + ZmqError());
  CAIRN_RETURN_IF_ERROR(SetLinkOptions(router_, options));
  CAIRN_RETURN_IF_ERROR(SetInt(router_, ZMQ_CURVE_SERVER, 1, "ZMQ_CURVE_SERVER"));
  CAIRN_RETURN_IF_ERROR(SetBytes(router_, ZMQ_CURVE_SECRETKEY, secret_key, "ZMQ_CURVE_SECRETKEY"));
  CAIRN_RETURN_IF_ERROR(SetBytes(router_, ZMQ_ZAP_DOMAIN, kZapDomain, "ZMQ_ZAP_DOMAIN"));
  const int64_t max_size = options.max_message_bytes;
  if (zmq_setsockopt(router_, ZMQ_MAXMSGSIZE, &max_size, sizeof(max_size)) != 0) {
    return InternalError("zmq_setsockopt ZMQ_MAXMSGSIZE: " + ZmqError());
  }
  if (zmq_bind(router_, options.listen.c_str()) != 0) {
    return UnavailableError("cannot listen at '" + options.listen + "': " + ZmqError());
  }
  char endpoint[256];
  size_t size = sizeof(endpoint);
  if (zmq_getsockopt(router_, ZMQ_LAST_ENDPOINT, endpoint, &size) == 0) bound_endpoint_ = endpoint;

  for (const ZmqPeer& p : peers) {
    void* dealer = zmq_socket(context_, ZMQ_DEALER);
    if (dealer == nullptr) return InternalError("zmq_socket (DEALER): " + ZmqError());
    dealers_[p.name] = dealer;
    CAIRN_RETURN_IF_ERROR(SetLinkOptions(dealer, options));
    // Only to a connected peer: a message queued for an absent one would only be stale later.
    CAIRN_RETURN_IF_ERROR(SetInt(dealer, ZMQ_IMMEDIATE, 1, "ZMQ_IMMEDIATE"));
    CAIRN_RETURN_IF_ERROR(SetInt(dealer, ZMQ_SNDHWM, static_cast<int>(options.send_queue_messages), "ZMQ_SNDHWM"));
    CAIRN_RETURN_IF_ERROR(
        SetInt(dealer, ZMQ_RECONNECT_IVL, Milliseconds(options.reconnect_interval), "ZMQ_RECONNECT_IVL"));
    CAIRN_RETURN_IF_ERROR(SetInt(dealer, ZMQ_RECONNECT_IVL_MAX, Milliseconds(options.reconnect_interval_max),
                                 "ZMQ_RECONNECT_IVL_MAX"));
    CAIRN_RETURN_IF_ERROR(SetBytes(dealer, ZMQ_CURVE_SERVERKEY, CurveKeys::Decode(p.public_key), "ZMQ_CURVE_SERVERKEY"));
    CAIRN_RETURN_IF_ERROR(SetBytes(dealer, ZMQ_CURVE_PUBLICKEY, public_key, "ZMQ_CURVE_PUBLICKEY"));
    CAIRN_RETURN_IF_ERROR(SetBytes(dealer, ZMQ_CURVE_SECRETKEY, secret_key, "ZMQ_CURVE_SECRETKEY"));
    if (zmq_connect(dealer, p.endpoint.c_str()) != 0) {
      return InvalidArgumentError("peer '" + p.name + "': cannot connect to '" + p.endpoint + "': " + ZmqError());
    }
    counters_.sent_bytes_by_peer[p.name] = 0;
    counters_.received_bytes_by_peer[p.name] = 0;
  }
  return Status::Ok();
}

ZmqTransport::~ZmqTransport() {
  for (auto& [name, dealer] : dealers_) zmq_close(dealer);
  if (router_ != nullptr) zmq_close(router_);
  if (context_ != nullptr) {
    // Wakes the ZAP thread out of its receive (ETERM); it closes its socket and ends.
    zmq_ctx_shutdown(context_);
    if (zap_thread_.joinable()) {
      zap_thread_.join();
    } else if (zap_ != nullptr) {
      zmq_close(zap_);
    }
    zmq_ctx_term(context_);
  }
}

void ZmqTransport::ServeZap() {
  // ZAP (RFC 27): version, request id, domain, address, identity, mechanism, credentials.
  while (true) {
    std::vector<std::string> frames;
    bool terminated = false;
    int more = 1;
    while (more != 0) {
      zmq_msg_t part;
      zmq_msg_init(&part);
      if (zmq_msg_recv(&part, zap_, 0) < 0) {
        zmq_msg_close(&part);
        if (zmq_errno() == EINTR) continue;
        terminated = true;
        break;
      }
      frames.emplace_back(static_cast<const char*>(zmq_msg_data(&part)), zmq_msg_size(&part));
      more = zmq_msg_more(&part);
      zmq_msg_close(&part);
    }
    if (terminated) break;
    std::string status = "400", text = "not a member of the team", user;
    if (frames.size() >= 7 && frames[0] == "1.0" && frames[5] == "CURVE") {
      const auto it = names_by_key_.find(frames[6]);
      if (it != names_by_key_.end()) {
        status = "200";
        text = "OK";
        user = it->second;
      }
    }
    if (status != "200") {
      std::lock_guard<std::mutex> lock(counters_mutex_);
      ++counters_.refused_unknown_key;
    }
    const std::string request_id = frames.size() >= 2 ? frames[1] : "";
    const std::string reply[] = {"1.0", request_id, status, text, user, ""};
    for (size_t i = 0; i < 6; ++i) {
      if (zmq_send(zap_, reply[i].data(), reply[i].size(), i + 1 < 6 ? ZMQ_SNDMORE : 0) < 0) break;
    }
  }
  zmq_close(zap_);
}

Status ZmqTransport::Send(const std::string& peer, const std::string& bytes) {
  const auto it = dealers_.find(peer);
  if (it == dealers_.end()) return NotFoundError("'" + peer + "' is not a teammate");
  if (zmq_send(it->second, bytes.data(), bytes.size(), ZMQ_DONTWAIT) < 0) {
    const int error = zmq_errno();
    std::lock_guard<std::mutex> lock(counters_mutex_);
    ++counters_.send_queue_full;
    return UnavailableError("to '" + peer + "': " + (error == EAGAIN ? "not connected or queue full" : ZmqError()));
  }
  std::lock_guard<std::mutex> lock(counters_mutex_);
  ++counters_.sent_messages;
  counters_.sent_bytes += bytes.size();
  counters_.sent_bytes_by_peer[peer] += bytes.size();
  return Status::Ok();
}

std::optional<ZmqMessage> ZmqTransport::Receive(Duration timeout) {
  while (true) {
    zmq_pollitem_t item{router_, 0, ZMQ_POLLIN, 0};
    const long ms = timeout.nanoseconds() <= 0 ? 0 : static_cast<long>((timeout.nanoseconds() + 999999) / 1000000);
    const int ready = zmq_poll(&item, 1, ms);
    if (ready <= 0 || (item.revents & ZMQ_POLLIN) == 0) return std::nullopt;
    zmq_msg_t id, data;
    zmq_msg_init(&id);
    if (zmq_msg_recv(&id, router_, ZMQ_DONTWAIT) < 0) {
      zmq_msg_close(&id);
      return std::nullopt;
    }
    const bool has_data = zmq_msg_more(&id) != 0;
    zmq_msg_close(&id);
    zmq_msg_init(&data);
    if (!has_data || zmq_msg_recv(&data, router_, ZMQ_DONTWAIT) < 0 || zmq_msg_more(&data) != 0) {
      zmq_msg_close(&data);
      Drain(router_);
      std::lock_guard<std::mutex> lock(counters_mutex_);
      ++counters_.refused_malformed;
      timeout = Duration();
      continue;
    }
    const char* user = zmq_msg_gets(&data, "User-Id");
    const auto named = user == nullptr ? names_by_key_.end() : std::find_if(names_by_key_.begin(), names_by_key_.end(),
                                                                            [&](const auto& kv) { return kv.second == user; });
    if (named == names_by_key_.end()) {
      // Cannot happen past the ZAP handler; refused rather than trusted.
      zmq_msg_close(&data);
      std::lock_guard<std::mutex> lock(counters_mutex_);
      ++counters_.refused_malformed;
      timeout = Duration();
      continue;
    }
    ZmqMessage message{named->second, std::string(static_cast<const char*>(zmq_msg_data(&data)), zmq_msg_size(&data))};
    zmq_msg_close(&data);
    std::lock_guard<std::mutex> lock(counters_mutex_);
    ++counters_.received_messages;
    counters_.received_bytes += message.bytes.size();
    counters_.received_bytes_by_peer[message.peer] += message.bytes.size();
    return message;
  }
}

ZmqTransportCounters ZmqTransport::counters() const {
  std::lock_guard<std::mutex> lock(counters_mutex_);
  return counters_;
}

}  // namespace cairn
