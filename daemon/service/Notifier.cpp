#include "daemon/service/Notifier.h"

#include <fmt/format.h>
#include <mosquitto.h>

#include <algorithm>
#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <optional>
#include <stdexcept>

namespace rotafab::service {
namespace {

namespace beast = boost::beast;
namespace http = beast::http;
using tcp = boost::asio::ip::tcp;

constexpr auto kTimeout = std::chrono::seconds(5);
constexpr size_t kMostWaiting = 1000;

}  // namespace

// One connection to the broker, made when the first event comes and made
// again after a failure; QoS 1, each publication waited for (PUBACK).
struct Notifier::Mqtt {
  mosquitto* client = nullptr;
  bool connected = false;
  int acknowledged = -1;
  Mqtt() {
    mosquitto_lib_init();
    client = mosquitto_new(nullptr, true, this);
    mosquitto_publish_callback_set(
        client, [](mosquitto*, void* self, int mid) { static_cast<Mqtt*>(self)->acknowledged = mid; });
  }
  ~Mqtt() {
    if (connected) mosquitto_disconnect(client);
    mosquitto_destroy(client);
    mosquitto_lib_cleanup();
  }
  Mqtt(const Mqtt&) = delete;
  Mqtt& operator=(const Mqtt&) = delete;
};

Notifier::Notifier(NotifyConfig config, std::shared_ptr<spdlog::logger> log)
    : config_(std::move(config)), log_(std::move(log)) {
  if (!config_.mqtt.empty()) mqtt_ = std::make_unique<Mqtt>();
  thread_ = std::thread([this] { deliver(); });
}

Notifier::~Notifier() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    stopBy_ = std::chrono::steady_clock::now() + std::chrono::seconds(3);
  }
  wake_.notify_all();
  thread_.join();
}

void Notifier::send(nlohmann::json event) {
  {
    std::lock_guard lock(mutex_);
    if (waiting_.size() >= kMostWaiting) {
      waiting_.pop_front();
      log_->warn("notifications: {} events waiting for their receivers; the oldest dropped", kMostWaiting);
    }
    waiting_.push_back(std::move(event));
  }
  wake_.notify_one();
}

void Notifier::deliver() {
  for (;;) {
    std::optional<nlohmann::json> event;
    {
      std::unique_lock lock(mutex_);
      wake_.wait_for(lock, std::chrono::seconds(1), [&] { return stopping_ || !waiting_.empty(); });
      // Stopping: what waits is delivered for 3 s at most (a receiver gone must not hold up the stop).
      if (stopping_ && (waiting_.empty() || std::chrono::steady_clock::now() > stopBy_)) return;
      if (!waiting_.empty()) {
        event = std::move(waiting_.front());
        waiting_.pop_front();
      }
    }
    if (!event) {
      keepAlive();
      continue;
    }
    // (A name in another encoding than UTF-8 is sent with its bytes replaced, not refused.)
    const std::string body = event->dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    for (const std::string& url : config_.webhooks) post(url, body);
    if (mqtt_) publish(event->value("event", "event"), body);
  }
}

void Notifier::keepAlive() {
  // The broker drops a client silent for 1.5 keepalives: its pings are sent from here.
  if (mqtt_ && mqtt_->connected && mosquitto_loop(mqtt_->client, 0, 1) != MOSQ_ERR_SUCCESS) {
    mosquitto_disconnect(mqtt_->client);
    mqtt_->connected = false;
  }
}

void Notifier::post(const std::string& url, const std::string& body) {
  try {
    const NotifyEndpoint to = webhookEndpoint(url);
    // Asynchronous steps on a stream whose expiry bounds the whole exchange
    // (a synchronous one would wait for ever on a receiver that never answers).
    boost::asio::io_context io;
    beast::tcp_stream stream(io);
    tcp::resolver resolver(io);
    http::request<http::string_body> request(http::verb::post, to.path, 11);
    request.set(http::field::host, to.host);
    request.set(http::field::user_agent, "rotafabd");
    request.set(http::field::content_type, "application/json");
    request.body() = body;
    request.prepare_payload();
    beast::flat_buffer buffer;
    http::response<http::string_body> response;
    beast::error_code failure;
    bool done = false;
    stream.expires_after(kTimeout);
    resolver.async_resolve(to.host, to.port, [&](beast::error_code error, const tcp::resolver::results_type& found) {
      if (error) return void(failure = error);
      stream.async_connect(found, [&](beast::error_code error, const tcp::endpoint&) {
        if (error) return void(failure = error);
        http::async_write(stream, request, [&](beast::error_code error, size_t) {
          if (error) return void(failure = error);
          http::async_read(stream, buffer, response, [&](beast::error_code error, size_t) {
            failure = error;
            done = !error;
          });
        });
      });
    });
    io.run_for(kTimeout + std::chrono::seconds(1));
    if (!done) return failed(url, failure ? failure.message() : std::string("no answer within 5 s"));
    beast::error_code ignored;
    stream.socket().shutdown(tcp::socket::shutdown_both, ignored);
    if (response.result_int() >= 300) {
      return failed(url, fmt::format("it answered {} {}", response.result_int(), std::string(response.reason())));
    }
    answered(url);
  } catch (const std::exception& error) {
    failed(url, error.what());
  }
}

void Notifier::publish(const std::string& kind, const std::string& body) {
  const std::string receiver = config_.mqtt;
  try {
    const NotifyEndpoint broker = mqttEndpoint(config_.mqtt);
    if (!mqtt_->connected) {
      const int status = mosquitto_connect(mqtt_->client, broker.host.c_str(), std::stoi(broker.port), 30);
      if (status != MOSQ_ERR_SUCCESS) {
        return failed(receiver,
                      status == MOSQ_ERR_ERRNO ? std::string(std::strerror(errno)) : mosquitto_strerror(status));
      }
      mqtt_->connected = true;
    }
    int mid = 0;
    const std::string topic = config_.topic + "/" + kind;
    const auto send = [&] {
      return mosquitto_publish(mqtt_->client, &mid, topic.c_str(), static_cast<int>(body.size()), body.data(), 1,
                               false);
    };
    int status = send();
    // Dropped by the broker since the last event: once more, on a new connection.
    if ((status == MOSQ_ERR_NO_CONN || status == MOSQ_ERR_CONN_LOST) &&
        mosquitto_reconnect(mqtt_->client) == MOSQ_ERR_SUCCESS) {
      status = send();
    }
    const auto until = std::chrono::steady_clock::now() + kTimeout;
    while (status == MOSQ_ERR_SUCCESS && mqtt_->acknowledged != mid && std::chrono::steady_clock::now() < until) {
      status = mosquitto_loop(mqtt_->client, 100, 1);
    }
    if (status != MOSQ_ERR_SUCCESS || mqtt_->acknowledged != mid) {
      mosquitto_disconnect(mqtt_->client);
      mqtt_->connected = false;
      return failed(receiver,
                    status != MOSQ_ERR_SUCCESS ? mosquitto_strerror(status) : "no acknowledgement within 5 s");
    }
    answered(receiver);
  } catch (const std::exception& error) {
    failed(receiver, error.what());
  }
}

void Notifier::failed(const std::string& receiver, const std::string& why) {
  if (std::find(silent_.begin(), silent_.end(), receiver) != silent_.end()) return;
  silent_.push_back(receiver);
  log_->warn("notifications: {} did not take an event: {} (said once until it takes one again)", receiver, why);
}

void Notifier::answered(const std::string& receiver) {
  if (const auto it = std::find(silent_.begin(), silent_.end(), receiver); it != silent_.end()) {
    silent_.erase(it);
    log_->info("notifications: {} takes events again", receiver);
  }
}

}  // namespace rotafab::service
