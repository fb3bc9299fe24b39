#include "core/WorkContext.h"

#include <spdlog/logger.h>
#include <spdlog/sinks/base_sink.h>

#include <mutex>

namespace rotafab::core {

void WorkContext::note(const std::string& text) const {
  if (log_) log_->info(text);
}

void WorkContext::warn(const std::string& text) const {
  if (log_) log_->warn(text);
}

namespace {

// Keeps each message with whether it was a warning (the work may say them from several threads).
template <typename Said>
class KeepingSink : public spdlog::sinks::base_sink<std::mutex> {
 public:
  explicit KeepingSink(std::shared_ptr<std::vector<Said>> said) : said_(std::move(said)) {}

 protected:
  void sink_it_(const spdlog::details::log_msg& message) override {
    said_->push_back(
        {message.level >= spdlog::level::warn, std::string(message.payload.data(), message.payload.size())});
  }
  void flush_() override {}

 private:
  std::shared_ptr<std::vector<Said>> said_;
};

}  // namespace

SaidLater::SaidLater()
    : said_(std::make_shared<std::vector<Said>>()),
      log_(std::make_shared<spdlog::logger>("said-later", std::make_shared<KeepingSink<Said>>(said_))) {
  log_->set_level(spdlog::level::info);
}

WorkContext SaidLater::context(const WorkContext& from, bool progress) const {
  return progress ? from.withLog(log_) : WorkContext(from.executor(), from.cancellation(), {}, log_);
}

void SaidLater::sayOn(const WorkContext& to) const {
  for (const Said& said : *said_) said.warning ? to.warn(said.text) : to.note(said.text);
}

}  // namespace rotafab::core
