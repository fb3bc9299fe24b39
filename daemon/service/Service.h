#pragma once
// The fabrication queue (docs/CONTRACT.md, "Daemon"): jobs submitted, planned once
// against their device's machine profile, cut one per device with a stop
// between sheets, and every change of state kept in the store before
// anyone is told of it.
//
// Threads: the daemon's one io_context runs the network; every piece of the
// queue's state (the store included) is touched only on one strand, so no
// lock guards it. Work that would hold that strand goes elsewhere: spool
// files are written on the worker pool, plans are made on the planners'
// pool (each plan on every core through the Executor), and each running job
// has a thread of its own for the driver, whose calls block on the device.
// Those post what they learn back to the strand.

#include <boost/asio/io_context.hpp>
#include <boost/asio/strand.hpp>
#include <boost/asio/thread_pool.hpp>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "daemon/service/ApiError.h"
#include "daemon/service/DaemonConfig.h"
#include "daemon/service/JobStore.h"
#include "daemon/service/Spool.h"
#include "daemon/service/Submission.h"

namespace spdlog {
class logger;
}

namespace rotafab::service {

// A reply: the JSON body, or the ApiError it became.
struct Reply {
  Reply() = default;
  Reply(int status, nlohmann::json body) : status(status), body(std::move(body)) {}
  int status = 200;
  nlohmann::json body;
  std::string text;            // the body already written as JSON (a long list, built a row at a time); else `body`
  std::filesystem::path file;  // or a file's bytes as the body (its type from its name)
  std::string contentType;     // of `text` when it is not JSON
  std::vector<std::pair<std::string, std::string>> headers;  // more header fields (Set-Cookie, Location)
};
using ReplyHandler = std::function<void(Reply)>;

// What a subscriber to the event stream is told: "job" (a transition: the
// job as status shows it), "progress" (of a plan or a cut), "device".
struct ServiceEvent {
  std::string type;
  nlohmann::json data;
};

class Service {
 public:
  Service(boost::asio::io_context& io, DaemonConfig config, std::shared_ptr<spdlog::logger> log);
  ~Service();
  Service(const Service&) = delete;
  Service& operator=(const Service&) = delete;

  // Opens the store and the spool, brings back what a stop left (running
  // jobs become interrupted, plans are made again), checks every device
  // (stopped safely, laser off confirmed; offline if it does not answer)
  // and starts the queue. Throws StoreError, ConfigError.
  void start();

  // The API. Each may be called from any thread; `done` is called once, on
  // the service's strand or pool (the caller posts it where it needs it).
  //
  // A new spool entry for an upload to be written into (UploadForm.h), which
  // submit() takes with it; ApiError when the daemon takes no submission now
  // (it is stopping: 503; the disk of its state is full: 507).
  Spool::Entry beginUpload();
  void submit(Submission submission, ReplyHandler done);
  void list(ReplyHandler done);
  void status(JobId id, ReplyHandler done);
  void manifest(JobId id, ReplyHandler done);
  void devices(ReplyHandler done);
  // A planned job's file for people to look at: a sheet's preview or cut
  // SVG, structure.obj, manifest.txt or manifest.json (Reply::file).
  void file(JobId id, const std::string& name, ReplyHandler done);
  // Sheet `sheet` (from 1) as its device's laser would burn it: the strokes
  // in order, each with its operation and pass, and the time it takes.
  void sheet(JobId id, int sheet, ReplyHandler done);
  // cancel, pause, resume, start, next, move, frame; `arguments`: resume's
  // from_sheet and from_stroke, move's before or priority, frame's sheet, as checkedActionArguments()
  // (ApiInput.h) left them; `who` for the record.
  void act(JobId id, const std::string& action, const nlohmann::json& arguments, const std::string& who,
           ReplyHandler done);

  // The event stream: `sink` is called on the strand for each event until unsubscribed.
  size_t subscribe(std::function<void(const ServiceEvent&)> sink);
  void unsubscribe(size_t id);

  // Stops every device safely, records each running job interrupted, and
  // calls `done` once all have stopped (on the strand).
  void shutdown(const std::string& why, std::function<void()> done);

  [[nodiscard]] const DaemonConfig& config() const { return config_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  DaemonConfig config_;
};

}  // namespace rotafab::service
