#include "cli/QueueCommands.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <regex>
#include <sstream>
#include <thread>

#include "cli/CommandSupport.h"
#include "cli/DaemonClient.h"
#include "cli/MakeOptionsCli.h"
#include "cli/RunProgress.h"
#include "core/Duration.h"
#include "jobs/Manifest.h"

namespace rotafab::cli {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// " (its kit: steps 174-352; once cut, steps 1-352 can be done)" for sheet
// `sheet` of a job whose summary gives its kits, else nothing.
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

struct ClientOptions {
  std::string server, token;
  bool json = false;
};

void addClientOptions(CLI::App& verb, ClientOptions& options, bool jsonFlag = true) {
  verb.add_option("--server", options.server,
                  "The daemon: unix:PATH or http://HOST:PORT (default: the Unix socket, "
                  "$XDG_RUNTIME_DIR/rotafab/rotafabd.sock)");
  verb.add_option("--token", options.token, "The bearer token a TCP listener asks for");
  if (jsonFlag) verb.add_flag("--json", options.json, "Print the daemon's JSON answer");
}

DaemonClient clientOf(const ClientOptions& options) {
  return DaemonClient(serverAddress(options.server, options.token));
}

// Runs a verb's body and reports its errors as one line, exit status 1.
template <typename Body>
int talking(Body&& body) {
  try {
    return body();
  } catch (const std::exception& error) {
    fmt::print(stderr, "error: {}\n", error.what());
    return kUserError;
  }
}

// Starts the desktop's browser on `url` (xdg-open), without waiting for
// it; false where there is no desktop or no xdg-open.
bool openInBrowser(const std::string& url) {
  const char* display = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  if ((!display || !*display) && (!wayland || !*wayland)) return false;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  // Its chatter is not ours to print.
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  std::string program = "xdg-open";
  std::vector<char*> argv{program.data(), const_cast<char*>(url.c_str()), nullptr};
  pid_t child = 0;
  const int error = ::posix_spawnp(&child, "xdg-open", &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (error != 0) return false;
  // xdg-open hands the link to a running browser and ends, failing when
  // none takes it; where it starts the browser itself it may stay as long
  // as the browser does: still running after 3 s, it has opened it.
  for (int tenth = 0; tenth < 30; ++tenth) {
    int exitStatus = 0;
    const pid_t ended = ::waitpid(child, &exitStatus, WNOHANG);
    if (ended == child) return WIFEXITED(exitStatus) && WEXITSTATUS(exitStatus) == 0;
    if (ended < 0) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return true;
}

std::string sheetsOf(const json& job) {
  const int sheets = job.value("sheets", 0);
  if (sheets == 0) return "-";
  return fmt::format("{}/{}", job.value("sheets_cut", 0), sheets);
}

std::string shortened(const std::string& text, size_t width) {
  return text.size() <= width ? text : text.substr(0, width - 3) + "...";
}

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

// How long `start` and `resume` wait for a device the daemon is still
// checking (its start: connected, stopped, laser off confirmed). The wait is
// here, in the command, so that Ctrl-C ends it and nothing starts after.
constexpr double kDeviceCheckPatience = 120;

void saysWaiting(const DaemonRefused& refused) {
  fmt::print(stderr,
             "waiting for the daemon's check of {} (connected, stopped, laser off confirmed); Ctrl-C gives up\n",
             refused.body.value("device", std::string("the device")));
}

long long jobNumber(const std::string& text) {
  try {
    size_t used = 0;
    const long long id = std::stoll(text, &used);
    if (used == text.size() && id > 0) return id;
  } catch (const std::exception&) {
  }
  throw UserError(fmt::format("{}: expected a job number (see `rotafab jobs`)", text));
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
    fmt::print("job {}: framing sheet {} (laser off); `rotafab status {}` says when it is framed\n",
               answer.value("id", 0), answer.value("framing_sheet", 0), answer.value("id", 0));
  } else if (action == "cancel" && state != "cancelled") {
    fmt::print("job {}: stopping (`rotafab status {}` says when it has)\n", answer.value("id", 0),
               answer.value("id", 0));
  } else {
    fmt::print("job {}: {}: {}\n", answer.value("id", 0), state, withCommand(answer, answer.value("id", 0LL)));
  }
}

}  // namespace

int runDaemonDevices(bool asJson, const std::string& server, const std::string& token) {
  return talking([&]() -> int {
    const json answer = DaemonClient(serverAddress(server, token)).get("/api/devices");
    if (asJson) {
      std::cout << answer.dump(1) << '\n';
      return kSuccess;
    }
    // On a shared store: every host's devices, each with its host, then the hosts.
    const bool shared = answer.contains("hosts");
    fmt::print("{:<10}  {}{:<9}  {:<16}  {:>4}  {}\n", "DEVICE", shared ? fmt::format("{:<12}  ", "HOST") : "", "STATE",
               "MACHINE", "JOB", "URI / MESSAGE");
    for (const json& device : answer["devices"]) {
      fmt::print("{:<10}  {}{:<9}  {:<16}  {:>4}  {}{}\n", device.value("name", ""),
                 shared ? fmt::format("{:<12}  ", device.value("host", "")) : "", device.value("state", ""),
                 device.value("machine", ""),
                 device["job"].is_null() ? "-" : std::to_string(device["job"].get<long long>()),
                 device.value("uri", ""), device.contains("message") ? ": " + device.value("message", "") : "");
    }
    if (shared) {
      std::string hosts;
      for (const json& host : answer["hosts"]) {
        const bool gone = host.value("state", "") == "gone";
        hosts += fmt::format("{}{} ({}{})", hosts.empty() ? "" : ", ", host.value("name", ""),
                             gone ? "gone, last heard " + host.value("seen", "") : "up",
                             host.value("address", "").empty() || gone ? "" : ", " + host.value("address", ""));
      }
      fmt::print("hosts on the shared job store: {}\n", hosts);
    }
    return kSuccess;
  });
}

int runDaemonManifest(long long job, const std::string& format, const std::string& server, const std::string& token) {
  return talking([&]() -> int {
    const json manifest = DaemonClient(serverAddress(server, token)).get(fmt::format("/api/jobs/{}/manifest", job));
    if (format == "json") {
      std::cout << manifest.dump(1) << '\n';
    } else if (format == "html") {
      throw UserError("--format html needs the sheets beside the manifest: run it on a `make` output folder");
    } else {
      std::cout << jobs::manifestText(manifest);
    }
    return kSuccess;
  });
}

namespace {

// The body of `submit`: a planned folder goes by its path, a mesh is uploaded with its `make` options.
int submitJob(const ClientOptions& client, const MakeOptions& make, const std::string& device, int priority,
              bool follows) {
  if (!make.out.empty())
    throw UserError("--out: the daemon keeps a submitted job's files; `rotafab make` writes a folder");
  const DaemonClient daemon = clientOf(client);
  // (--json is submit's own here: how the job is printed.)
  MakeOptions sent = make;
  sent.given.erase("json");
  const std::vector<std::string> words = jobs::optionWords(sent);
  std::error_code error;
  json job;
  if (fs::is_directory(make.mesh, error)) {
    if (!words.empty()) {
      throw UserError(fmt::format("{}: a planned folder is cut as `make` made it; {} is an option for a mesh",
                                  make.mesh, words.front()));
    }
    json body{{"path", fs::absolute(make.mesh).lexically_normal().string()}, {"priority", priority}};
    if (!device.empty()) body["device"] = device;
    job = daemon.post("/api/jobs", body);
  } else {
    std::ifstream in(make.mesh, std::ios::binary);
    if (!in) throw UserError(fmt::format("{}: cannot read the file", make.mesh));
    std::ostringstream bytes;
    bytes << in.rdbuf();
    std::vector<std::pair<std::string, std::string>> fields{{"options", jobs::optionsJson(sent).dump()},
                                                            {"priority", std::to_string(priority)}};
    if (!device.empty()) fields.emplace_back("device", device);
    job = daemon.upload("/api/jobs", fs::path(make.mesh).filename().string(), bytes.str(), fields);
  }
  if (make.json) {
    std::cout << job.dump() << '\n';
  } else {
    fmt::print("job {}: {} {}{}\n", job.value("id", 0), job.value("source", ""),
               job.value("state", "") == "queued" ? "queued" : "submitted",
               job["device"].is_string() ? " for " + job["device"].get<std::string>() : "");
  }
  // A planned folder is checked as it is submitted: its job is ready at once.
  if (settled(job)) {
    if (!make.json)
      fmt::print("job {}: {}: {}\n", job.value("id", 0), job.value("state", ""),
                 withCommand(job, job.value("id", 0LL)));
    return kSuccess;
  }
  if (follows) return follow(daemon, job.value("id", 0LL));
  if (!make.json) fmt::print("follow it with `rotafab status {} --follow`\n", job.value("id", 0));
  return kSuccess;
}

void addSubmitCommand(CLI::App& app, int& status) {
  auto client = std::make_shared<ClientOptions>();
  auto make = std::make_shared<MakeOptions>();
  auto device = std::make_shared<std::string>();
  auto priority = std::make_shared<int>(0);
  auto follows = std::make_shared<bool>(false);
  CLI::App* submit = app.add_subcommand(
      "submit", "Queue a mesh (planned with `make` options) or a `make` output folder on the daemon");
  addMakeOptions(*submit, *make);
  submit->get_option("MESH")->description("A mesh file (uploaded), or a `make` output folder on the daemon's machine");
  submit->get_option("--structure")->required(false);
  submit->get_option("--out")->description("(not for submit: the daemon keeps the job's files)");
  submit->get_option("--json")->description("Print the job as the daemon's JSON");
  submit->add_option("--device", *device, "The device to cut on (default: any device whose machine profile fits)");
  submit->add_option("--priority", *priority, "Higher is cut first (default 0)");
  submit->add_flag("--follow", *follows, "Then follow the job until it is planned (or fails)");
  addClientOptions(*submit, *client, false);
  submit->footer(
      "The job is planned once, against its device's machine profile; it is cut only after `rotafab start JOB`\n"
      "(unless the device has auto_start), with a stop before each sheet after the first (`rotafab next JOB`).\n\n"
      "Examples:\n"
      "  rotafab submit examples/bunny.obj --structure band --follow\n"
      "  rotafab submit examples/cube.obj --structure band --device laser1 --priority 5\n"
      "  rotafab submit $PWD/cube-band/          # a folder `rotafab make` wrote, cut as it is");
  submit->callback([submit, client, make, device, priority, follows, &status] {
    std::error_code isFolder;
    if (make->structure.empty() && !fs::is_directory(make->mesh, isFolder)) {
      throw CLI::ValidationError("--structure is required to plan a mesh (band or weave)");
    }
    checkStructureOptions(*submit, *make);
    status = talking([&]() -> int { return submitJob(*client, *make, *device, *priority, *follows); });
  });
}

void addJobsCommand(CLI::App& app, int& status) {
  auto client = std::make_shared<ClientOptions>();
  CLI::App* jobs = app.add_subcommand("jobs", "List the daemon's jobs in queue order");
  addClientOptions(*jobs, *client);
  jobs->footer("Examples:\n  rotafab jobs\n  rotafab jobs --json");
  jobs->callback([client, &status] {
    status = talking([&]() -> int {
      const json answer = clientOf(*client).get("/api/jobs");
      if (client->json) {
        std::cout << answer.dump(1) << '\n';
      } else {
        printJobs(answer["jobs"]);
      }
      return kSuccess;
    });
  });
}

void addStatusCommand(CLI::App& app, int& status) {
  auto client = std::make_shared<ClientOptions>();
  auto job = std::make_shared<std::string>();
  auto follows = std::make_shared<bool>(false);
  CLI::App* statusVerb = app.add_subcommand("status", "A job's state, progress and history");
  statusVerb->add_option("JOB", *job, "The job's number")->required();
  statusVerb->add_flag("--follow", *follows,
                       "Show live progress until the job is done, fails, is cancelled or interrupted, or is planned");
  addClientOptions(*statusVerb, *client);
  statusVerb->footer("Examples:\n  rotafab status 7\n  rotafab status 7 --follow");
  statusVerb->callback([client, job, follows, &status] {
    status = talking([&]() -> int {
      const long long id = jobNumber(*job);
      const DaemonClient daemon = clientOf(*client);
      if (*follows) return follow(daemon, id);
      const json answer = daemon.get(fmt::format("/api/jobs/{}", id));
      if (client->json) {
        std::cout << answer.dump(1) << '\n';
      } else {
        printStatus(answer);
      }
      return kSuccess;
    });
  });
}

// cancel, pause, start, next: a job number and nothing else.
void addJobActionCommand(CLI::App& app, int& status, const char* verb, const char* help) {
  auto client = std::make_shared<ClientOptions>();
  auto job = std::make_shared<std::string>();
  CLI::App* command = app.add_subcommand(verb, help);
  command->add_option("JOB", *job, "The job's number")->required();
  addClientOptions(*command, *client);
  command->footer(fmt::format("Examples:\n  rotafab {} 7\n  rotafab {} 7 --json", verb, verb));
  const std::string name = verb;
  command->callback([client, job, name, &status] {
    status = talking([&]() -> int {
      const json answer = clientOf(*client).postPatiently(fmt::format("/api/jobs/{}/{}", jobNumber(*job), name),
                                                          json::object(), kDeviceCheckPatience, saysWaiting);
      printAnswer(answer, name, client->json);
      return kSuccess;
    });
  });
}

void addResumeCommand(CLI::App& app, int& status) {
  auto client = std::make_shared<ClientOptions>();
  auto job = std::make_shared<std::string>();
  auto fromSheet = std::make_shared<std::optional<int>>();
  auto fromStroke = std::make_shared<std::optional<int>>();
  auto wholeSheet = std::make_shared<bool>(false);
  CLI::App* resume =
      app.add_subcommand("resume", "Go on with a paused job, or an interrupted or failed one from a sheet");
  resume->add_option("JOB", *job, "The job's number")->required();
  resume
      ->add_option("--from-sheet", *fromSheet,
                   "For an interrupted or failed job: the sheet to go on with (the one it stopped in, left where "
                   "it is, goes on from its first stroke not cut; another is cut whole, loaded fresh)")
      ->check(CLI::PositiveNumber);
  auto* stroke = resume
                     ->add_option("--from-stroke", *fromStroke,
                                  "The stroke of that sheet to go on from (default: the first not cut)")
                     ->check(CLI::PositiveNumber);
  resume->add_flag("--whole-sheet", *wholeSheet, "Cut the sheet whole again (a fresh one loaded)")->excludes(stroke);
  addClientOptions(*resume, *client);
  resume->footer(
      "A job the daemon was cutting when it stopped comes back interrupted and never restarts by itself:\n"
      "check the machine, then resume it from the sheet it stopped in. Left where it was, that sheet is\n"
      "framed (laser off) and waits until you say it is in place (`rotafab next JOB`), then goes on from\n"
      "the first stroke not cut; the strokes cut are not cut again.\n\n"
      "Examples:\n"
      "  rotafab resume 7\n"
      "  rotafab resume 7 --from-sheet 3\n"
      "  rotafab resume 7 --from-sheet 3 --whole-sheet");
  resume->callback([client, job, fromSheet, fromStroke, wholeSheet, &status] {
    status = talking([&]() -> int {
      json body = json::object();
      if (*fromSheet) body["from_sheet"] = **fromSheet;
      if (*fromStroke) body["from_stroke"] = **fromStroke;
      if (*wholeSheet) body["from_stroke"] = 1;
      try {
        printAnswer(clientOf(*client).postPatiently(fmt::format("/api/jobs/{}/resume", jobNumber(*job)), body,
                                                    kDeviceCheckPatience, saysWaiting),
                    "resume", client->json);
      } catch (const DaemonRefused& refused) {
        // The daemon asks for the sheet in its own words; here, the option that gives it.
        if (*fromSheet || std::string_view(refused.what()).find("say which sheet to go on from") == std::string::npos)
          throw;
        throw UserError(fmt::format("{}: give it with --from-sheet N", refused.what()));
      }
      return kSuccess;
    });
  });
}

void addFrameCommand(CLI::App& app, int& status) {
  auto client = std::make_shared<ClientOptions>();
  auto job = std::make_shared<std::string>();
  auto sheet = std::make_shared<std::optional<int>>();
  CLI::App* frame = app.add_subcommand("frame", "Trace a sheet's box on the machine with the laser off, to check it");
  frame->add_option("JOB", *job, "The job's number")->required();
  frame->add_option("--sheet", *sheet, "The sheet (default: the one the job goes on with)")->check(CLI::PositiveNumber);
  addClientOptions(*frame, *client);
  frame->footer(
      "The head goes round the box of the sheet's cuts with the laser off, so that you can check the sheet\n"
      "is where the cut will be. A job waiting between sheets frames the one it waits for, and waits again;\n"
      "a ready, interrupted or failed job is framed on the device it would be cut on.\n\n"
      "Examples:\n"
      "  rotafab frame 7\n"
      "  rotafab frame 7 --sheet 2");
  frame->callback([client, job, sheet, &status] {
    status = talking([&]() -> int {
      json body = json::object();
      if (*sheet) body["sheet"] = **sheet;
      printAnswer(clientOf(*client).postPatiently(fmt::format("/api/jobs/{}/frame", jobNumber(*job)), body,
                                                  kDeviceCheckPatience, saysWaiting),
                  "frame", client->json);
      return kSuccess;
    });
  });
}

void addMoveCommand(CLI::App& app, int& status) {
  auto client = std::make_shared<ClientOptions>();
  auto job = std::make_shared<std::string>();
  auto before = std::make_shared<std::string>();
  auto device = std::make_shared<std::string>();
  auto priority = std::make_shared<std::optional<int>>();
  CLI::App* move = app.add_subcommand(
      "move", "Reorder the queue (a job before another, or a new priority), or move a job to another device");
  move->add_option("JOB", *job, "The job's number")->required();
  auto* beforeOption = move->add_option("--before", *before, "Put it just before this job (and at its priority)");
  auto* priorityOption =
      move->add_option("--priority", *priority, "Its new priority (higher is cut first)")->excludes(beforeOption);
  move->add_option("--device", *device,
                   "Cut it on this device instead: a queued, ready, interrupted or failed job (a ready one made "
                   "from a mesh is planned again where the device's machine differs)")
      ->excludes(beforeOption)
      ->excludes(priorityOption);
  addClientOptions(*move, *client);
  move->footer(
      "Examples:\n  rotafab move 9 --before 7\n  rotafab move 9 --priority 5\n  rotafab move 9 --device laser2");
  move->callback([client, job, before, priority, device, &status] {
    status = talking([&]() -> int {
      json body = json::object();
      if (!before->empty()) body["before"] = jobNumber(*before);
      if (*priority) body["priority"] = **priority;
      if (!device->empty()) body["device"] = *device;
      if (body.empty()) throw UserError("move: give --before OTHER, --priority P or --device NAME");
      const DaemonClient daemon = clientOf(*client);
      const json moved = daemon.post(fmt::format("/api/jobs/{}/move", jobNumber(*job)), body);
      if (!device->empty()) {
        printAnswer(moved, "move", client->json);
        return kSuccess;
      }
      const json answer = daemon.get("/api/jobs");
      if (client->json) {
        std::cout << answer.dump(1) << '\n';
      } else {
        printJobs(answer["jobs"]);
      }
      return kSuccess;
    });
  });
}

void addDashboardCommand(CLI::App& app, int& status) {
  auto client = std::make_shared<ClientOptions>();
  auto urlOnly = std::make_shared<bool>(false);
  CLI::App* dashboard =
      app.add_subcommand("dashboard", "Open the workshop page (queue, machines, previews, assembly guide) signed in");
  dashboard->add_flag("--url", *urlOnly, "Only print the one-time login link, for a browser you open yourself");
  addClientOptions(*dashboard, *client);
  dashboard->footer(
      "The daemon serves the page on loopback TCP (http://127.0.0.1:8730 unless that port was taken: rotafabd.json\n"
      "in its state directory says where). A browser gets in only with a session, which a one-time link\n"
      "opens: this command asks the daemon for one over its Unix socket, as this machine's user, and opens\n"
      "it in the browser. The link works once, within five minutes; the session lasts a week unused.\n\n"
      "Examples:\n"
      "  rotafab dashboard\n"
      "  rotafab dashboard --url          # print the link only (another browser, a tablet over SSH tunnel)");
  dashboard->callback([client, urlOnly, &status] {
    status = talking([&]() -> int {
      const json link = clientOf(*client).post("/api/sessions", json::object());
      const std::string url = link.value("url", "");
      if (client->json) {
        std::cout << link.dump(1) << '\n';
        return kSuccess;
      }
      if (*urlOnly) {
        fmt::print("{}\n", url);
        return kSuccess;
      }
      if (openInBrowser(url)) {
        fmt::print("opened the workshop page in your browser; the link works once, within five minutes:\n{}\n", url);
      } else {
        fmt::print("open this link in a browser on this machine (it works once, within five minutes):\n{}\n", url);
      }
      return kSuccess;
    });
  });
}

}  // namespace

// The verbs are added in the order `rotafab --help` lists them.
void addQueueCommands(CLI::App& app, int& status) {
  addSubmitCommand(app, status);
  addJobsCommand(app, status);
  addStatusCommand(app, status);
  addJobActionCommand(app, status, "cancel", "Cancel a job; a cut stops with the laser off");
  addJobActionCommand(app, status, "pause", "Hold a running cut (feed hold); `rotafab resume JOB` goes on");
  addResumeCommand(app, status);
  addJobActionCommand(app, status, "start", "Cut a planned job on its device, from its first sheet (load it first)");
  addJobActionCommand(app, status, "next", "Say the next sheet is loaded (or a framed one in place): the job cuts it");
  addFrameCommand(app, status);
  addMoveCommand(app, status);
  addDashboardCommand(app, status);
}

}  // namespace rotafab::cli
