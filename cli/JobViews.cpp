#include "cli/JobViews.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <regex>
#include <thread>

#include "cli/CommandSupport.h"
#include "cli/RunProgress.h"
#include "core/Duration.h"

namespace rotafab::cli {
namespace fs = std::filesystem;
using nlohmann::json;

// What to load for `sheet`, where the job's summary says it: ", posterboard
// (0.8 mm), 32 x 18 in (its kit: steps 181-364; ...)".
std::string whatToLoad(const json& job, int sheet) {
  const json* summary = job.contains("summary") && job["summary"].is_object() ? &job["summary"] : nullptr;
  std::string said;
  if (summary && summary->contains("stock") && (*summary)["stock"].is_string()) {
    said = ", " + (*summary)["stock"].get<std::string>();
  }
  const json* kits = summary && summary->contains("kits") ? &(*summary)["kits"] : nullptr;
  if (!kits || !kits->is_array() || sheet < 1 || static_cast<size_t>(sheet) > kits->size()) return said;
  const json& kit = (*kits)[static_cast<size_t>(sheet) - 1];
  if (kit.is_string() && !kit.get<std::string>().empty()) said += fmt::format(" (its kit: {})", kit.get<std::string>());
  return said;
}

namespace {

std::string sheetsOf(const json& job) {
  const int sheets = job.value("sheets", 0);
  if (sheets == 0) return "-";
  return fmt::format("{}/{}", job.value("sheets_cut", 0), sheets);
}

}  // namespace

namespace {

std::string shortened(const std::string& text, size_t width) {
  return text.size() <= width ? text : text.substr(0, width - 3) + "...";
}

}  // namespace

void printJobs(const json& jobs) {
  if (jobs.empty()) {
    fmt::print("no jobs; submit one with `rotafab submit MESH --structure band`\n");
    return;
  }
  // On a shared store the host that plans or cuts a job is shown with its device: laser2@room-2.
  const bool hosts =
      std::any_of(jobs.begin(), jobs.end(), [](const json& job) { return job.value("host", json()).is_string(); });
  const int width = hosts ? 18 : 10;
  fmt::print("{:>4}  {:<11}  {:<{}}  {:>6}  {:<10}  {:<22}  {}\n", "ID", "STATE", hosts ? "DEVICE@HOST" : "DEVICE",
             width, "SHEETS", "OWNER", "SOURCE", "NOTE");
  for (const json& job : jobs) {
    std::string device = job["device"].is_string() ? job["device"].get<std::string>() : "any";
    if (job.value("host", json()).is_string()) device += "@" + job["host"].get<std::string>();
    std::string state = job.value("state", "");
    if (job.value("waiting_for_next", false)) state += "*";
    fmt::print("{:>4}  {:<11}  {:<{}}  {:>6}  {:<10}  {:<22}  {}\n", job.value("id", 0), state, device, width,
               sheetsOf(job), shortened(job.value("owner", ""), 10),
               shortened(fs::path(job.value("source", "")).filename().string(), 22),
               shortened(job.value("device_missing", job.value("message", "")), 70));
  }
  if (std::any_of(jobs.begin(), jobs.end(), [](const json& job) { return job.value("waiting_for_next", false); })) {
    fmt::print("* waiting for the next sheet to be loaded: `rotafab next ID` once it is\n");
  }
}

namespace {

std::string progressLine(const json& progress) {
  if (progress.value("phase", "") == "cutting") {
    const double strokes = std::max(1.0, progress.value("strokes", 0.0));
    const int percent = static_cast<int>(100 * progress.value("stroke", 0.0) / strokes);
    const int filled = percent / 5;
    return fmt::format("sheet {} of {} [{}{}] {:3}%  stroke {} of {}, {} left", progress.value("sheet", 0),
                       progress.value("sheets", 0), std::string(filled, '#'), std::string(20 - filled, '.'), percent,
                       progress.value("stroke", 0), progress.value("strokes", 0),
                       core::minutes(progress.value("seconds_left", 0.0)));
  }
  std::string line = fmt::format("planning: {}", progress.value("phase", ""));
  if (!progress.value("step", "").empty()) line += ": " + progress.value("step", "");
  if (progress.value("total", 0) > 0)
    line += fmt::format(" {} of {}", progress.value("done", 0), progress.value("total", 0));
  if (progress.contains("layout_sheets")) line += fmt::format(", {} sheets", progress.value("layout_sheets", 0));
  return line;
}

}  // namespace

// A job's message with the command that goes on from it, for the command
// line (the daemon's messages are in its own words, which the page shows
// beside its buttons): "planned: 3 sheets; start it with
// `rotafab start 7`".
std::string withCommand(const json& job, long long id) {
  if (job.contains("device_missing") && job["device_missing"].is_string()) {
    return fmt::format(
        "{}; {}: move it to another device with `rotafab move {} --device NAME` (`rotafab "
        "devices --daemon` lists them)",
        job.value("message", ""), job["device_missing"].get<std::string>(), id);
  }
  const std::string message = job.value("message", ""), state = job.value("state", "");
  if (state == "ready") return message + fmt::format("; start it with `rotafab start {}`", id);
  // The sheet the daemon says to go on from, where it says one (a stop or a device's fault).
  static const std::regex goOn(R"((?:load|leave) sheet (\d+) (?:and|where it is and) resume from it)");
  if (std::smatch sheet; (state == "interrupted" || state == "failed") && std::regex_search(message, sheet, goOn)) {
    return message + fmt::format(" (`rotafab resume {} --from-sheet {}`)", id, sheet[1].str());
  }
  return message;
}

namespace {

// What a job waiting for its operator waits for, with the commands that answer it.
std::string waitingSaid(const json& job, long long id) {
  const int sheet = job.value("waiting_sheet", job.value("sheet", 0) + 1);
  if (job.value("waiting_for", "").find("framed") != std::string::npos) {
    return fmt::format("{}: run `rotafab next {}` (`rotafab frame {}` frames it again)", job.value("waiting_for", ""),
                       id, id);
  }
  return fmt::format("load sheet {}{} and run `rotafab next {}` (`rotafab frame {}` frames it first)", sheet,
                     whatToLoad(job, sheet), id, id);
}

}  // namespace

void printStatus(const json& job) {
  const std::string device = job["device"].is_string() ? job["device"].get<std::string>() : "any device that fits";
  fmt::print("job {}: {} ({}), {}\n", job.value("id", 0), job.value("source", ""), job.value("kind", ""),
             job.value("state", ""));
  fmt::print("  owner {}, device {}, priority {}, submitted {}\n", job.value("owner", ""), device,
             job.value("priority", 0), job.value("submitted", ""));
  if (job.contains("summary") && job["summary"].is_object()) {
    const json& summary = job["summary"];
    std::string line =
        fmt::format("  {} sheet{}", summary.value("sheets", 0), summary.value("sheets", 0) == 1 ? "" : "s");
    if (summary.contains("panels")) line += fmt::format(", {} panels", summary.value("panels", 0));
    if (summary.contains("fasteners")) line += fmt::format(", {} fasteners", summary.value("fasteners", 0));
    if (summary.contains("utilization"))
      line += fmt::format(", {:.0f}% of the material", 100 * summary.value("utilization", 0.0));
    if (summary.contains("cost") && summary["cost"].contains("cutting_seconds")) {
      line += fmt::format(", about {} to cut", core::minutes(summary["cost"].value("cutting_seconds", 0.0)));
    }
    fmt::print("{}\n", line);
    if (summary.contains("stock") && summary["stock"].is_string()) {
      fmt::print("  sheets of {}, cut on {}\n", summary["stock"].get<std::string>(), summary.value("machine", ""));
    }
    // What the plan warned of, as make says it: the builders should know.
    if (summary.contains("warnings") && summary["warnings"].is_array()) {
      for (const json& warning : summary["warnings"]) {
        if (warning.is_string()) fmt::print("  warning: {}\n", warning.get<std::string>());
      }
    }
  }
  if (job.contains("progress")) fmt::print("  {}\n", progressLine(job["progress"]));
  if (job.value("waiting_for_next", false)) fmt::print("  waiting: {}\n", waitingSaid(job, job.value("id", 0LL)));
  fmt::print("  {}\n", withCommand(job, job.value("id", 0LL)));
  if (job.contains("events") && job["events"].is_array() && !job["events"].empty()) {
    const json& latest = job["events"].back();
    fmt::print("  latest: {} ({})\n", latest.value("text", ""), latest.value("at", ""));
  }
  if (job.contains("transitions")) {
    fmt::print("  history:\n");
    for (const json& t : job["transitions"]) {
      fmt::print("    {}  {:<11} {}\n", t.value("at", ""), t.value("to", ""), t.value("reason", ""));
    }
  }
}

bool settled(const json& job) {
  const std::string state = job.value("state", "");
  return state == "done" || state == "failed" || state == "cancelled" || state == "interrupted" || state == "ready";
}

// Follows a job's events until it settles: done, failed, cancelled,
// interrupted, or ready (planned: an operator starts it).
int follow(const DaemonClient& client, long long id) {
  const bool terminal = ::isatty(STDERR_FILENO) != 0;
  // At a terminal, Enter says the next sheet is loaded, as `rotafab run` asks.
  const bool askHere = terminal && ::isatty(STDIN_FILENO) != 0;
  json job = client.get(fmt::format("/api/jobs/{}", id));
  printStatus(job);
  if (settled(job)) return job.value("state", "") == "failed" ? kDeviceFault : kSuccess;
  std::string lastState = job.value("state", ""), lastLine;
  bool barShown = false;
  int lastSheet = 0, askedFor = 0;
  const auto endBar = [&] {
    if (barShown && terminal) fmt::print(stderr, "\n");
    barShown = false;
  };
  core::Cancellation stopAsking;
  std::thread asking;
  const auto stopAsker = [&] {
    stopAsking.cancel();
    if (asking.joinable()) asking.join();
  };
  int status = kSuccess;
  try {
    client.events(fmt::format("/api/events?job={}", id), [&](const std::string& type, const json& data) {
      if (type == "progress") {
        if (data.value("phase", "") == "cutting" && data.value("sheet", 0) != lastSheet) {
          endBar();
          lastSheet = data.value("sheet", 0);
        }
        const std::string line = progressLine(data);
        if (terminal) {
          fmt::print(stderr, "\r{:<90}", line);
          barShown = true;
        } else {
          // Without a terminal, a line at each tenth of a sheet, and at each step of a plan (its
          // counts every tenth).
          const std::string decile =
              data.value("phase", "") == "cutting"
                  ? fmt::format("{}/{}", data.value("sheet", 0),
                                10 * data.value("stroke", 0) / std::max(1, data.value("strokes", 0)))
                  : fmt::format("{}/{}/{}", data.value("phase", ""), data.value("step", ""),
                                10 * data.value("done", 0) / std::max(1, data.value("total", 0)));
          if (decile != lastLine) fmt::print(stderr, "{}\n", line);
          lastLine = decile;
        }
        return true;
      }
      if (type != "job") return true;
      const std::string state = data.value("state", "");
      const bool waiting = data.value("waiting_for_next", false);
      const int next = data.value("waiting_sheet", data.value("sheet", 0) + 1);
      const bool framed = data.value("waiting_for", "").find("framed") != std::string::npos;
      if (state != lastState) {
        endBar();
        fmt::print(stderr, "job {}: {}: {}\n", id, state, withCommand(data, id));
        lastState = state;
      }
      if (waiting && askedFor != next * 2 + (framed ? 1 : 0)) {
        endBar();
        askedFor = next * 2 + (framed ? 1 : 0);
        if (askHere) {
          fmt::print(stderr, "job {}: {} press Enter (or run `rotafab next {}`; `rotafab frame {}` frames it)\n", id,
                     framed ? fmt::format("sheet {} framed: once it is in place,", next)
                            : fmt::format("load sheet {}{}, then", next, whatToLoad(data, next)),
                     id, id);
          if (asking.joinable()) asking.join();
          asking = std::thread([&client, id, &stopAsking] {
            if (!waitForEnter(stopAsking)) return;
            try {
              client.post(fmt::format("/api/jobs/{}/next", id), json::object());
            } catch (const std::exception& error) {
              fmt::print(stderr, "error: {}\n", error.what());
            }
          });
        } else {
          fmt::print(stderr, "job {}: {}\n", id, waitingSaid(data, id));
        }
      }
      if (settled(data)) {
        status = state == "failed" ? kDeviceFault : kSuccess;
        return false;
      }
      return true;
    });
  } catch (...) {
    stopAsker();
    throw;
  }
  stopAsker();
  return status;
}

// The job as an action left it ("job 7: running: started by alice"), or,
// for a cancel the daemon answered before the device or the plan stopped, that it is stopping.
void printAnswer(const json& answer, const std::string& action, bool asJson) {
  const std::string state = answer.value("state", "");
  if (asJson) {
    std::cout << answer.dump() << '\n';
  } else if (answer.contains("asked_host")) {
    fmt::print("job {}: {} on host {}: asked it to {} it (`rotafab status {}` says when it has)\n",
               answer.value("id", 0), state, answer.value("asked_host", ""), action, answer.value("id", 0));
  } else if (action == "frame") {
    fmt::print("job {}: framing sheet {} ({}); `rotafab status {}` says when it is framed\n", answer.value("id", 0),
               answer.value("framing_sheet", 0), answer.value("frame_light", "laser off"), answer.value("id", 0));
  } else if (action == "cancel" && state != "cancelled") {
    fmt::print("job {}: stopping (`rotafab status {}` says when it has)\n", answer.value("id", 0),
               answer.value("id", 0));
  } else {
    fmt::print("job {}: {}: {}\n", answer.value("id", 0), state, withCommand(answer, answer.value("id", 0LL)));
  }
}

}  // namespace rotafab::cli
