#pragma once
// The event stream (docs/API.md, GET /api/events): server-sent events of
// the service's transitions, progress and devices, on a connection the
// server hands over once the gate has admitted it. A client that does not
// read falls behind and is dropped, never waited for; a client that goes
// away is seen at once (its end of the socket readable).
//
// Threads: everything on the connection's executor; the service's events,
// which come on its strand, are posted there.

#include <fmt/format.h>

#include <boost/asio/steady_timer.hpp>
#include <boost/asio/write.hpp>
#include <chrono>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "daemon/service/Service.h"

namespace rotafab::service {

template <typename Socket>
class EventStream : public std::enable_shared_from_this<EventStream<Socket>> {
 public:
  // `socket` belongs to `owner` (the connection, kept alive until the
  // stream ends); `closeConnection` closes it. `onlyJob`: only that job's
  // events, and every device's.
  EventStream(Socket& socket, Service& service, std::optional<int64_t> onlyJob, std::shared_ptr<void> owner,
              std::function<void()> closeConnection)
      : socket_(socket),
        service_(service),
        onlyJob_(onlyJob),
        owner_(std::move(owner)),
        closeConnection_(std::move(closeConnection)) {}

  void start() {
    queue_.push_back(
        "HTTP/1.1 200 OK\r\nServer: rotafabd\r\nContent-Type: text/event-stream\r\nCache-Control: no-cache\r\n"
        "Connection: close\r\n\r\n: rotafabd events\n\n");
    writeNext();
    auto weak = std::weak_ptr<EventStream>(this->shared_from_this());
    const auto executor = socket_.get_executor();
    subscription_ = service_.subscribe([weak, executor, onlyJob = onlyJob_](const ServiceEvent& event) {
      if (onlyJob && event.type != "device" &&
          event.data.value("job", event.data.value("id", int64_t{0})) != *onlyJob) {
        return;
      }
      std::string text = fmt::format("event: {}\ndata: {}\n\n", event.type,
                                     event.data.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
      boost::asio::post(executor, [weak, text = std::move(text)]() mutable {
        if (auto self = weak.lock()) self->send(std::move(text));
      });
    });
    subscribed_ = true;
    heartbeat();
    socket_.async_wait(Socket::wait_read,
                       [self = this->shared_from_this()](boost::system::error_code) { self->end(); });
  }

  // Unsubscribed, the connection closed and let go; once.
  void end() {
    if (ended_) return;
    ended_ = true;
    if (subscribed_) service_.unsubscribe(subscription_);
    if (timer_) timer_->cancel();
    closeConnection_();
    owner_.reset();
  }

 private:
  // A comment line every 15 s: proxies and browsers keep a quiet stream open.
  void heartbeat() {
    timer_ = std::make_unique<boost::asio::steady_timer>(socket_.get_executor(), std::chrono::seconds(15));
    timer_->async_wait([weak = std::weak_ptr<EventStream>(this->shared_from_this())](boost::system::error_code error) {
      auto self = weak.lock();
      if (error || !self || self->ended_) return;
      self->send(": keep-alive\n\n");
      self->heartbeat();
    });
  }

  void send(std::string text) {
    if (ended_) return;
    if (queue_.size() > 1000) return end();
    queue_.push_back(std::move(text));
    if (queue_.size() == 1) writeNext();
  }

  void writeNext() {
    if (queue_.empty() || ended_) return;
    boost::asio::async_write(socket_, boost::asio::buffer(queue_.front()),
                             [self = this->shared_from_this()](boost::system::error_code error, size_t) {
                               if (error) return self->end();
                               self->queue_.pop_front();
                               self->writeNext();
                             });
  }

  Socket& socket_;
  Service& service_;
  std::optional<int64_t> onlyJob_;
  std::shared_ptr<void> owner_;
  std::function<void()> closeConnection_;
  std::deque<std::string> queue_;
  size_t subscription_ = 0;
  bool subscribed_ = false, ended_ = false;
  std::unique_ptr<boost::asio::steady_timer> timer_;
};

}  // namespace rotafab::service
