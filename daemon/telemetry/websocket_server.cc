// Built as C++17 (see websocket_server.h).
#define ASIO_STANDALONE
#include "daemon/telemetry/websocket_server.h"

#include <atomic>
#include <deque>
#include <map>
#include <mutex>
#include <thread>

#include <sys/resource.h>

#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>

namespace cairn {

namespace {
using Server = websocketpp::server<websocketpp::config::asio>;
using Handle = websocketpp::connection_hdl;
// Bytes a client may have in flight in the socket before we hold further messages back.
constexpr size_t kMaxInFlight = 4 << 20;
}  // namespace

struct WebSocketServer::Impl {
  struct Client {
    Handle handle;
    std::deque<std::pair<bool, std::string>> queue;  // (binary, payload)
  };

  Server server;
  std::thread thread;
  std::string subprotocol;
  size_t max_queued = 256;
  Callbacks callbacks;
  std::atomic<uint16_t> port{0};
  std::atomic<uint64_t> dropped{0};
  std::atomic<size_t> clients_connected{0};
  double cpu_seconds = 0.0;
  std::mutex mutex;  // guards clients and ids
  std::map<uint64_t, Client> clients;
  std::map<Handle, uint64_t, std::owner_less<Handle>> ids;
  uint64_t next_id = 1;
  bool running = false;
  std::unique_ptr<asio::steady_timer> pump_timer;

  void Enqueue(uint64_t client, bool binary, std::string payload) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      auto it = clients.find(client);
      if (it == clients.end()) return;
      auto& q = it->second.queue;
      if (q.size() >= max_queued) {
        q.pop_front();
        dropped.fetch_add(1, std::memory_order_relaxed);
      }
      q.emplace_back(binary, std::move(payload));
    }
    asio::post(server.get_io_service(), [this] { Pump(); });
  }

  // On the server thread: hand queued messages to websocketpp while the socket keeps up.
  void Pump() {
    std::vector<std::pair<Handle, std::pair<bool, std::string>>> ready;
    {
      std::lock_guard<std::mutex> lock(mutex);
      for (auto& [id, c] : clients) {
        websocketpp::lib::error_code ec;
        auto con = server.get_con_from_hdl(c.handle, ec);
        if (ec) continue;
        size_t in_flight = con->get_buffered_amount();
        while (!c.queue.empty() && in_flight < kMaxInFlight) {
          in_flight += c.queue.front().second.size();
          ready.emplace_back(c.handle, std::move(c.queue.front()));
          c.queue.pop_front();
        }
      }
    }
    for (auto& [h, m] : ready) {
      websocketpp::lib::error_code ec;
      server.send(h, m.second, m.first ? websocketpp::frame::opcode::binary : websocketpp::frame::opcode::text, ec);
      // A send error means the client is going away; its close handler cleans up.
    }
  }

  void SchedulePump() {
    pump_timer->expires_after(std::chrono::milliseconds(10));
    pump_timer->async_wait([this](const asio::error_code& ec) {
      if (ec) return;
      Pump();
      SchedulePump();
    });
  }
};

WebSocketServer::WebSocketServer() : impl_(std::make_unique<Impl>()) {}

WebSocketServer::~WebSocketServer() { Stop(); }

bool WebSocketServer::Start(const std::string& address, uint16_t port, const std::string& subprotocol,
                            size_t max_queued, Callbacks callbacks, std::string* error) {
  Impl& s = *impl_;
  s.subprotocol = subprotocol;
  s.max_queued = max_queued < 1 ? 1 : max_queued;
  s.callbacks = std::move(callbacks);
  try {
    s.server.clear_access_channels(websocketpp::log::alevel::all);
    s.server.clear_error_channels(websocketpp::log::elevel::all);
    s.server.init_asio();
    s.server.set_reuse_addr(true);
    s.server.set_validate_handler([&s](Handle h) {
      auto con = s.server.get_con_from_hdl(h);
      for (const std::string& p : con->get_requested_subprotocols()) {
        if (p == s.subprotocol) {
          con->select_subprotocol(p);
          return true;
        }
      }
      con->set_status(websocketpp::http::status_code::bad_request);
      return false;
    });
    s.server.set_open_handler([&s](Handle h) {
      uint64_t id;
      {
        std::lock_guard<std::mutex> lock(s.mutex);
        id = s.next_id++;
        s.clients[id] = Impl::Client{h, {}};
        s.ids[h] = id;
      }
      s.clients_connected.fetch_add(1);
      if (s.callbacks.on_open) s.callbacks.on_open(id);
    });
    const auto closed = [&s](Handle h) {
      uint64_t id = 0;
      {
        std::lock_guard<std::mutex> lock(s.mutex);
        auto it = s.ids.find(h);
        if (it == s.ids.end()) return;
        id = it->second;
        s.ids.erase(it);
        s.clients.erase(id);
      }
      s.clients_connected.fetch_sub(1);
      if (s.callbacks.on_close) s.callbacks.on_close(id);
    };
    s.server.set_close_handler(closed);
    s.server.set_fail_handler(closed);
    s.server.set_message_handler([&s](Handle h, Server::message_ptr msg) {
      if (msg->get_opcode() != websocketpp::frame::opcode::text) return;  // no client publishing
      uint64_t id = 0;
      {
        std::lock_guard<std::mutex> lock(s.mutex);
        auto it = s.ids.find(h);
        if (it == s.ids.end()) return;
        id = it->second;
      }
      if (s.callbacks.on_text) s.callbacks.on_text(id, msg->get_payload());
    });
    asio::error_code ec;
    const auto ip = asio::ip::make_address(address, ec);
    if (ec) {
      *error = "invalid listen address '" + address + "'";
      return false;
    }
    s.server.listen(asio::ip::tcp::endpoint(ip, port));
    s.server.start_accept();
    websocketpp::lib::error_code lec;
    const auto endpoint = s.server.get_local_endpoint(lec);
    s.port = lec ? port : endpoint.port();
  } catch (const std::exception& e) {
    *error = "cannot listen on " + address + ":" + std::to_string(port) + ": " + e.what();
    return false;
  }
  s.pump_timer = std::make_unique<asio::steady_timer>(s.server.get_io_service());
  s.SchedulePump();
  s.running = true;
  s.thread = std::thread([&s] {
    try {
      s.server.run();
    } catch (const std::exception&) {
      // The server thread must not take the daemon down; the stream simply ends.
    }
    rusage usage{};
    if (getrusage(RUSAGE_THREAD, &usage) == 0) {
      s.cpu_seconds = static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
                      static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) * 1e-6;
    }
  });
  return true;
}

void WebSocketServer::Stop() {
  Impl& s = *impl_;
  if (!s.running) return;
  s.running = false;
  asio::post(s.server.get_io_service(), [&s] {
    websocketpp::lib::error_code ec;
    s.pump_timer->cancel();
    s.server.stop_listening(ec);
    std::vector<Handle> handles;
    {
      std::lock_guard<std::mutex> lock(s.mutex);
      for (auto& [id, c] : s.clients) handles.push_back(c.handle);
    }
    for (auto& h : handles) s.server.close(h, websocketpp::close::status::going_away, "server stopping", ec);
  });
  // Give clients a moment to receive the close frame, then stop regardless.
  for (int i = 0; i < 50 && s.clients_connected.load() > 0; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  s.server.stop();
  if (s.thread.joinable()) s.thread.join();
}

uint16_t WebSocketServer::port() const { return impl_->port.load(); }

void WebSocketServer::SendText(uint64_t client, std::string text) { impl_->Enqueue(client, false, std::move(text)); }

void WebSocketServer::SendBinary(uint64_t client, std::string bytes) { impl_->Enqueue(client, true, std::move(bytes)); }

void WebSocketServer::Close(uint64_t client, const std::string& reason) {
  Impl& s = *impl_;
  asio::post(s.server.get_io_service(), [&s, client, reason] {
    Handle h;
    {
      std::lock_guard<std::mutex> lock(s.mutex);
      auto it = s.clients.find(client);
      if (it == s.clients.end()) return;
      h = it->second.handle;
    }
    websocketpp::lib::error_code ec;
    s.server.close(h, websocketpp::close::status::policy_violation, reason, ec);
  });
}

uint64_t WebSocketServer::dropped_messages() const { return impl_->dropped.load(); }

double WebSocketServer::cpu_seconds() const { return impl_->cpu_seconds; }

size_t WebSocketServer::client_count() const { return impl_->clients_connected.load(); }

}  // namespace cairn
