#pragma once
// What every long step of a job is handed instead of process-wide state: the
// executor to run in parallel on, the cancellation to check, where progress
// goes, and the logger for notes and warnings. The caller owns each of them
// and keeps them alive while the work runs; a daemon makes one context per
// job, the command line one per command.

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/Cancellation.h"
#include "core/Executor.h"
#include "core/Progress.h"

// Declared, not included: spdlog's headers cost seconds in every file that
// includes this one, and only WorkContext.cpp writes to the logger.
namespace spdlog {
class logger;
}

namespace rotafab::core {

class WorkContext {
 public:
  // `log` may be null: notes and warnings then go nowhere (they are also
  // returned with the results that have them).
  WorkContext(Executor& executor, const Cancellation& cancellation, ProgressSink progress = {},
              std::shared_ptr<spdlog::logger> log = nullptr)
      : executor_(executor), cancellation_(cancellation), progress_(std::move(progress)), log_(std::move(log)) {}

  [[nodiscard]] Executor& executor() const { return executor_; }
  [[nodiscard]] const Cancellation& cancellation() const { return cancellation_; }
  [[nodiscard]] bool cancelled() const { return cancellation_.cancelled(); }
  // Throws Cancelled once the work has been cancelled.
  void check() const { cancellation_.check(); }

  void report(const Progress& progress) const {
    if (progress_) progress_(progress);
  }
  [[nodiscard]] bool reportsProgress() const { return static_cast<bool>(progress_); }

  void note(const std::string& text) const;
  void warn(const std::string& text) const;
  [[nodiscard]] const std::shared_ptr<spdlog::logger>& log() const { return log_; }

  // The same executor, cancellation and logger, with progress going to `progress` instead.
  [[nodiscard]] WorkContext withProgress(ProgressSink progress) const {
    return WorkContext(executor_, cancellation_, std::move(progress), log_);
  }

  // The same executor, cancellation and progress, with notes and warnings going to `log` instead.
  [[nodiscard]] WorkContext withLog(std::shared_ptr<spdlog::logger> log) const {
    return WorkContext(executor_, cancellation_, progress_, std::move(log));
  }

  // parallelFor on the executor, checking the cancellation before each index.
  template <typename Body>
  void parallelFor(size_t count, Body&& body) const {
    executor_.parallelFor(count, [&](size_t i) {
      check();
      body(i);
    });
  }

 private:
  Executor& executor_;
  const Cancellation& cancellation_;
  ProgressSink progress_;
  std::shared_ptr<spdlog::logger> log_;
};

// What a piece of work says (its notes and warnings), kept to be said
// later, or never: a try whose result may be thrown away says nothing of
// itself until it is kept.
class SaidLater {
 public:
  SaidLater();
  // `from`'s executor and cancellation, its notes and warnings kept here;
  // its progress too, or none (`progress` false).
  [[nodiscard]] WorkContext context(const WorkContext& from, bool progress = true) const;
  // Says what was kept, in the order said, on `to`.
  void sayOn(const WorkContext& to) const;

 private:
  struct Said {
    bool warning;
    std::string text;
  };
  std::shared_ptr<std::vector<Said>> said_;
  std::shared_ptr<spdlog::logger> log_;
};

}  // namespace rotafab::core
