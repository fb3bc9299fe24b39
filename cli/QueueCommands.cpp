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
#include "cli/JobViews.h"
#include "cli/MakeOptionsCli.h"
#include "cli/RunProgress.h"
#include "core/Duration.h"
#include "jobs/Manifest.h"

namespace rotafab::cli {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

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

int runDaemonManifest(long long job, const std::string& format, const std::string& server, const std::string& token,
                      const std::string& units) {
  return talking([&]() -> int {
    const json manifest = DaemonClient(serverAddress(server, token)).get(fmt::format("/api/jobs/{}/manifest", job));
    if (format == "json") {
      std::cout << manifest.dump(1) << '\n';
    } else if (format == "html") {
      throw UserError("--format html needs the sheets beside the manifest: run it on a `make` output folder");
    } else {
      std::cout << jobs::manifestText(manifest, unitShown(units, jobs::displayUnitOf(manifest)));
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
      "framed (laser off, or at the machine's frame_power) and waits until you say it is in place (`rotafab next "
      "JOB`), then goes on from\n"
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
  CLI::App* frame = app.add_subcommand("frame", "Trace a sheet's box on the machine, to check where it lies");
  frame->add_option("JOB", *job, "The job's number")->required();
  frame->add_option("--sheet", *sheet, "The sheet (default: the one the job goes on with)")->check(CLI::PositiveNumber);
  addClientOptions(*frame, *client);
  frame->footer(
      "The head goes round the box of the sheet's cuts with the laser off (or lit at the machine profile's\n"
      "frame_power, a few percent), so that you can check the sheet\n"
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
