// rotafabd as a process, through its socket: jobs submitted, planned,
// started and cut to their end by the client; the stops between sheets;
// kills at any instant; SIGTERM mid-cut; many clients at once; hostile
// requests; a full disk; a device's fault.

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/mount.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <fstream>
#include <map>
#include <mutex>
#include <random>
#include <regex>
#include <set>
#include <thread>
#include <tuple>

#include "daemon/DaemonSupport.h"
#include "daemon/service/DaemonConfig.h"
#include "daemon/service/JobStore.h"
#include "support/TestDatabase.h"

namespace rotafab::test {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

TEST(Daemon, AMeshIsSubmittedPlannedStartedAndCutToItsEndThroughTheClient) {
  TempDir root;
  Daemon daemon(root.path());
  daemon.start();
  // Planned once, against the device's machine profile; nothing cuts before an operator starts it.
  const CommandResult submitted =
      daemon.client("submit " + quoted(kSource / "examples/cube.obj") + " --structure band --follow");
  ASSERT_EQ(submitted.status, 0) << submitted.out << submitted.err;
  EXPECT_NE(submitted.out.find("job 1: cube.obj queued\n"), std::string::npos) << submitted.out;
  EXPECT_NE(submitted.err.find("job 1: ready: planned: 1 sheet; start it with `rotafab start 1`"), std::string::npos)
      << submitted.err;
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_EQ(state(daemon.job(1)), "ready");
  const CommandResult started = daemon.client("start 1");
  ASSERT_EQ(started.status, 0) << started.err;
  const CommandResult followed = daemon.client("status 1 --follow");
  EXPECT_EQ(followed.status, 0) << followed.err;
  EXPECT_NE(followed.err.find("job 1: done: cut on laser1: 1 sheet"), std::string::npos) << followed.err;
  const json job = daemon.clientJson("status 1");
  EXPECT_EQ(job["state"], "done");
  EXPECT_EQ(job["owner"], daemon.clientJson("jobs")["jobs"][0]["owner"]);
  std::vector<std::string> states;
  for (const json& t : job["transitions"]) states.push_back(t["to"]);
  EXPECT_EQ(states, (std::vector<std::string>{"queued", "planning", "ready", "running", "done"}));
  EXPECT_EQ(job["summary"]["panels"], 6);
  // The manifest of the planned job, from the daemon.
  const CommandResult manifest = daemon.client("manifest 1");
  EXPECT_EQ(manifest.status, 0) << manifest.err;
  EXPECT_NE(manifest.out.find("6 panels on 1 sheet"), std::string::npos) << manifest.out;
  const json devices = daemon.clientJson("devices --daemon");
  ASSERT_EQ(devices["devices"].size(), 1u);
  EXPECT_EQ(devices["devices"][0]["state"], "idle");
  // At its start the daemon stopped the device and the controller confirmed its laser off.
  EXPECT_NE(devices["devices"][0].value("checked", "").find("laser off confirmed"), std::string::npos)
      << devices.dump();
  // Done is final.
  const CommandResult again = daemon.client("start 1");
  EXPECT_EQ(again.status, 1);
  EXPECT_EQ(again.err, "error: job 1 is done; only a ready job can be started\n");
}

TEST(Daemon, EachSheetAfterTheFirstWaitsForNextAndACutCanBePausedAndResumed) {
  TempDir root;
  Daemon daemon(root.path(), "devices: [{name: laser1, machine: grbl-diode-400, uri: \"sim:grbl?speed=200\"}]\n");
  daemon.start();
  const json submitted = daemon.clientJson("submit " + quoted(threeSheets()));
  const long long id = submitted["id"];
  EXPECT_EQ(submitted["kind"], "planned");
  ASSERT_EQ(state(daemon.waitForJob(id, [](const json& j) { return state(j) == "ready"; })), "ready");
  EXPECT_EQ(daemon.job(id)["sheets"], 3);
  ASSERT_EQ(daemon.client(fmt::format("start {}", id)).status, 0);
  // Paused mid-sheet: the device holds, and says so.
  json job =
      daemon.waitForJob(id, [](const json& j) { return j.contains("progress") && j["progress"]["stroke"] >= 2; });
  ASSERT_EQ(daemon.client(fmt::format("pause {}", id)).status, 0);
  EXPECT_EQ(state(daemon.job(id)), "paused");
  EXPECT_EQ(daemon.clientJson("devices --daemon")["devices"][0]["state"], "paused");
  const json held = daemon.job(id);
  std::this_thread::sleep_for(std::chrono::milliseconds(600));
  // (A stroke the controller had buffered may still be acknowledged; no more.)
  EXPECT_LE(daemon.job(id)["progress"]["stroke"].get<int>(), held["progress"]["stroke"].get<int>() + 2);
  ASSERT_EQ(daemon.client(fmt::format("resume {}", id)).status, 0);
  EXPECT_EQ(state(daemon.job(id)), "running");
  for (int sheet = 2; sheet <= 3; ++sheet) {
    job = daemon.waitForJob(
        id, [](const json& j) { return j.value("waiting_for_next", false); }, 120);
    ASSERT_TRUE(job.value("waiting_for_next", false)) << job.dump();
    EXPECT_EQ(job["sheet"], sheet - 1);
    EXPECT_EQ(state(job), "running");
    // The sheets cut are counted as they are cut.
    EXPECT_EQ(job["sheets_cut"], sheet - 1) << job.dump();
    EXPECT_TRUE(std::regex_search(daemon.client("jobs").out,
                                  std::regex(fmt::format(R"(running\*?\s+laser1(@\S+)?\s+{}/3\s)", sheet - 1))))
        << daemon.client("jobs").out;
    // The operator is told what to load (the material, its thickness, the
    // sheet's size), and what the builders can do once it is cut.
    const std::string stock = job["summary"].value("stock", "");
    EXPECT_TRUE(stock.starts_with("posterboard (0.8 mm), ")) << job.dump();
    const CommandResult status = daemon.client(fmt::format("status {}", id));
    EXPECT_NE(status.out.find(fmt::format("waiting: load sheet {}, {} (its kit: steps ", sheet, stock)),
              std::string::npos)
        << status.out;
    // Nothing moves while it waits: a pause has nothing to hold.
    EXPECT_EQ(daemon.client(fmt::format("pause {}", id)).status, 1);
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    EXPECT_TRUE(daemon.job(id).value("waiting_for_next", false));
    const CommandResult next = daemon.client(fmt::format("next {}", id));
    ASSERT_EQ(next.status, 0) << next.err;
  }
  job = daemon.waitForJob(
      id, [](const json& j) { return state(j) == "done"; }, 120);
  ASSERT_EQ(state(job), "done") << job.dump();
  EXPECT_EQ(job["sheet"], 3);
  const CommandResult late = daemon.client(fmt::format("next {}", id));
  EXPECT_EQ(late.status, 1);
  EXPECT_NE(late.err.find("is done"), std::string::npos) << late.err;
}

TEST(Daemon, AKillAtAnyInstantLosesNoAcceptedJobAndRestartsNoCut) {
  TempDir root;
  Daemon daemon(root.path(), "devices: [{name: laser1, machine: grbl-diode-400, uri: \"sim:grbl?speed=50\"}]\n");
  std::mt19937 random(20261202);
  std::set<long long> accepted;
  std::set<long long> everRunning;
  const int iterations = 8;
  for (int iteration = 0; iteration < iterations; ++iteration) {
    daemon.start();
    // Whatever is ready is started, so that some kills land mid-cut.
    for (const json& job : json(daemon.clientJson("jobs")["jobs"])) {
      if (state(job) == "ready") {
        if (daemon.client(fmt::format("start {}", job["id"].get<long long>())).status == 0) {
          everRunning.insert(job["id"].get<long long>());
          break;
        }
      }
    }
    // Submissions go on while the kill comes: meshes (planned by the daemon) and planned folders.
    std::mutex mutex;
    std::atomic<bool> stop{false};
    std::thread submitter([&] {
      for (int i = 0; !stop; ++i) {
        const std::string what = i % 2 == 0
                                     ? quoted(threeSheets())
                                     : quoted(kSource / "examples/soccer-ball.obj") + " --structure band --time 1";
        const CommandResult r = daemon.client("submit " + what + " --json");
        if (r.status != 0) break;  // the kill
        const json job = json::parse(r.out, nullptr, false);
        std::lock_guard lock(mutex);
        if (job.is_object()) accepted.insert(job["id"].get<long long>());
      }
    });
    // (The sanitizers' build is slower at everything: its windows are longer, for the same instants.)
    std::this_thread::sleep_for(std::chrono::milliseconds(
        static_cast<int>(kPromisedDelayScale * std::uniform_int_distribution<int>(100, 1500)(random))));
    daemon.kill9();
    stop = true;
    submitter.join();
    {
      auto store = service::openSqliteStore(daemon.stateDir() / "jobs.sqlite3");
      EXPECT_EQ(store->integrityCheck(), "ok") << "iteration " << iteration;
      for (long long id : accepted) EXPECT_TRUE(store->job(id)) << "job " << id << " was accepted and is lost";
    }
    daemon.start();
    const json jobs = daemon.clientJson("jobs")["jobs"];
    for (const json& job : jobs) {
      EXPECT_NE(state(job), "running") << job.dump();
      EXPECT_NE(state(job), "paused") << job.dump();
      if (state(job) == "interrupted") {
        EXPECT_NE(job.value("message", "").find("the daemon stopped while it cut"), std::string::npos) << job.dump();
        EXPECT_TRUE(everRunning.contains(job["id"].get<long long>()));
      }
    }
    // Nothing starts by itself.
    std::this_thread::sleep_for(std::chrono::milliseconds(800));
    for (const json& job : json(daemon.clientJson("jobs")["jobs"])) EXPECT_NE(state(job), "running") << job.dump();
    daemon.kill9();
  }
  // Kills landed among the submissions (each iteration's window holds several, unless the machine is slow).
  EXPECT_GE(accepted.size(), static_cast<size_t>(iterations / 2));
  // An interrupted job goes on only when an operator resumes it, from the sheet they say.
  daemon.start();
  std::optional<long long> interrupted;
  for (const json& job : json(daemon.clientJson("jobs")["jobs"])) {
    if (state(job) == "interrupted") interrupted = job["id"].get<long long>();
  }
  if (interrupted) {
    const CommandResult bare = daemon.client(fmt::format("resume {}", *interrupted));
    EXPECT_EQ(bare.status, 1);
    EXPECT_NE(bare.err.find("--from-sheet N"), std::string::npos) << bare.err;
    const int sheets = daemon.job(*interrupted)["sheets"];
    ASSERT_EQ(daemon.client(fmt::format("resume {} --from-sheet {}", *interrupted, sheets)).status, 0);
    const json done = daemon.waitForJob(
        *interrupted, [](const json& j) { return state(j) == "done"; }, 120);
    EXPECT_EQ(state(done), "done") << done.dump();
  }
}

TEST(Daemon, SigtermMidCutLeavesTheSimulatedLaserOffAndTheJobInterrupted) {
  TempDir root;
  const fs::path witness = root.path() / "laser";
  Daemon daemon(root.path(), witnessedLaser(5, witness));
  daemon.start();
  const long long id = cuttingThreeSheets(daemon);
  ASSERT_NE(id, 0);
  daemon.signal(SIGTERM);
  EXPECT_EQ(daemon.wait(30), 0) << readFile(daemon.log());
  // The simulated controller saw its laser lit, then off, and nothing after.
  const std::string changes = readFile(witness);
  EXPECT_NE(changes.find("on\n"), std::string::npos) << changes;
  EXPECT_TRUE(changes.ends_with("off\n")) << changes;
  daemon.start();
  const json job = daemon.job(id);
  EXPECT_EQ(state(job), "interrupted") << job.dump();
  EXPECT_NE(job.value("message", "").find("the daemon stopped at sheet 1 of 3"), std::string::npos) << job.dump();
  EXPECT_NE(job.value("message", "").find("laser off"), std::string::npos) << job.dump();
  // The daemon says it in its own words, which the page shows; the command line adds its command.
  EXPECT_TRUE(job.value("message", "").find("to go on, load sheet 1 and resume from it") != std::string::npos ||
              job.value("message", "").find("to go on, leave sheet 1 where it is and resume from it") !=
                  std::string::npos)
      << job.dump();
  EXPECT_EQ(job.value("message", "").find("rotafab"), std::string::npos) << job.dump();
  const CommandResult status = daemon.client(fmt::format("status {}", id));
  EXPECT_NE(status.out.find(fmt::format(" (`rotafab resume {} --from-sheet 1`)\n", id)), std::string::npos)
      << status.out;
  const json last = job["transitions"].back();
  EXPECT_EQ(last["from"], "running");
  EXPECT_EQ(last["to"], "interrupted");
  // Resumed from the last sheet: its progress is said in the job's own sheet numbers.
  ASSERT_EQ(daemon.client(fmt::format("resume {} --from-sheet 3", id)).status, 0);
  const json resumed = daemon.waitForJob(id, [](const json& j) { return j.contains("progress"); });
  EXPECT_EQ(resumed["progress"]["sheet"], 3) << resumed.dump();
  EXPECT_EQ(resumed["sheet"], 3) << resumed.dump();
  daemon.client(fmt::format("cancel {}", id));
  const json cancelled = daemon.waitForJob(id, [](const json& j) { return state(j) == "cancelled"; });
  EXPECT_NE(cancelled.value("message", "").find("at sheet 3 of 3"), std::string::npos) << cancelled.dump();
}

// Whether the job's events, newest last, say `text`.
bool saidInEvents(const json& job, const std::string& text) {
  if (!job.contains("events")) return false;
  return std::any_of(job["events"].begin(), job["events"].end(),
                     [&](const json& event) { return event.value("text", "").find(text) != std::string::npos; });
}

TEST(Daemon, ASheetIsFramedLaserOffAndAStoppedOneGoesOnFromTheStrokeItStoppedAtOnceSaidInPlace) {
  TempDir root;
  const fs::path witness = root.path() / "laser";
  Daemon daemon(root.path(), witnessedLaser(5, witness));
  daemon.start();
  const long long id = daemon.clientJson("submit " + quoted(threeSheets()))["id"];
  ASSERT_EQ(state(daemon.waitForJob(id, [](const json& j) { return state(j) == "ready"; })), "ready");
  // A ready job's sheet framed on its device: the head moves, the laser stays off, the job stays ready.
  const CommandResult frame = daemon.client(fmt::format("frame {} --sheet 2", id));
  ASSERT_EQ(frame.status, 0) << frame.err;
  EXPECT_NE(frame.out.find("framing sheet 2 (laser off)"), std::string::npos) << frame.out;
  json job = daemon.waitForJob(id, [](const json& j) { return saidInEvents(j, "sheet 2 framed on laser1"); });
  ASSERT_TRUE(saidInEvents(job, "sheet 2 framed on laser1 (laser off)")) << job.dump();
  EXPECT_EQ(state(job), "ready");
  EXPECT_EQ(readFile(witness).find("on\n"), std::string::npos) << "lit while framing";
  EXPECT_NE(daemon.client(fmt::format("status {}", id)).out.find("latest: sheet 2 framed on laser1"),
            std::string::npos);
  // Cut until some strokes are surely cut, then the daemon stopped.
  ASSERT_EQ(daemon.client(fmt::format("start {}", id)).status, 0);
  job = daemon.waitForJob(
      id, [](const json& j) { return j.value("/progress/cut"_json_pointer, 0) >= 4; }, 60);
  ASSERT_GE(job.value("/progress/cut"_json_pointer, 0), 4) << job.dump();
  daemon.signal(SIGTERM);
  ASSERT_EQ(daemon.wait(30), 0) << readFile(daemon.log());
  daemon.start();
  job = daemon.job(id);
  ASSERT_EQ(state(job), "interrupted") << job.dump();
  const int cut = job["stroke"].get<int>(), strokes = job["strokes"].get<int>();
  ASSERT_GE(cut, 4) << job.dump();
  ASSERT_LT(cut, strokes) << job.dump();
  EXPECT_NE(job.value("message", "").find(fmt::format("with {} of its {} strokes cut", cut, strokes)),
            std::string::npos)
      << job.dump();
  EXPECT_NE(job.value("message", "").find(fmt::format("goes on from stroke {} once you say it is in place", cut + 1)),
            std::string::npos)
      << job.dump();
  const std::string litBefore = readFile(witness);
  // Resumed: the sheet is framed, and the job waits for the operator, the laser off.
  ASSERT_EQ(daemon.client(fmt::format("resume {} --from-sheet 1", id)).status, 0);
  job = daemon.waitForJob(
      id, [](const json& j) { return j.value("waiting_for_next", false); }, 60);
  ASSERT_TRUE(job.value("waiting_for_next", false)) << job.dump();
  EXPECT_EQ(job.value("waiting_for", ""),
            fmt::format("sheet 1 framed: once it is in place, go on from stroke {}", cut + 1));
  const CommandResult status = daemon.client(fmt::format("status {}", id));
  EXPECT_NE(status.out.find(fmt::format("`rotafab next {}`", id)), std::string::npos) << status.out;
  // Framed again on request, and waiting again.
  ASSERT_EQ(daemon.client(fmt::format("frame {}", id)).status, 0);
  job = daemon.waitForJob(
      id, [](const json& j) { return j.value("waiting_for_next", false); }, 60);
  ASSERT_TRUE(job.value("waiting_for_next", false)) << job.dump();
  EXPECT_EQ(daemon.client(fmt::format("frame {} --sheet 3", id)).status, 1) << "only the sheet it waits for";
  EXPECT_EQ(readFile(witness), litBefore) << "lit before the operator said the sheet is in place";
  // Told it is in place: it goes on from the first stroke not cut.
  ASSERT_EQ(daemon.client(fmt::format("next {}", id)).status, 0);
  job = daemon.waitForJob(id, [](const json& j) { return j.contains("progress") && j["progress"].contains("cut"); });
  EXPECT_GE(job.value("/progress/stroke"_json_pointer, 0), cut) << job.dump();
  job = daemon.job(id);
  EXPECT_TRUE(saidInEvents(job, fmt::format("sheet 1 of 3 goes on from stroke {}", cut + 1))) << job.dump();
  daemon.client(fmt::format("cancel {}", id));
  job = daemon.waitForJob(id, [](const json& j) { return state(j) == "cancelled"; });
  EXPECT_TRUE(readFile(witness).ends_with("off\n"));
}

// A kill -9 mid-cut: the job is interrupted at a stroke no more than a few
// behind what the laser had cut (the lit moves the simulated controller
// finished), and never ahead of it.
TEST(Daemon, AKillMidCutKeepsWhereTheCutWasToAFewStrokes) {
  TempDir root;
  const fs::path cuts = root.path() / "cuts";
  Daemon daemon(root.path(),
                fmt::format("devices: [{{name: laser1, machine: grbl-diode-400, uri: \"sim:grbl?speed=2&cuts={}\"}}]\n",
                            cuts.string()));
  daemon.start();
  const long long id = cuttingThreeSheets(daemon);
  ASSERT_NE(id, 0);
  daemon.waitForJob(
      id, [](const json& j) { return j.value("/progress/cut"_json_pointer, 0) >= 6; }, 60);
  daemon.kill9();
  daemon.wait(10);
  const std::string said = readFile(cuts);
  const auto finished = static_cast<size_t>(std::count(said.begin(), said.end(), '\n'));
  daemon.start();
  const json job = daemon.job(id);
  ASSERT_EQ(state(job), "interrupted") << job.dump();
  // The strokes whose every lit move (segment) had finished, in cutting order.
  const json sheet = daemon.get(fmt::format("/api/jobs/{}/sheets/1", id)).body;
  size_t segments = 0, cut = 0;
  for (const json& stroke : sheet["strokes"]) {
    const json& points = stroke["points"];
    for (size_t i = 1; i < points.size(); ++i) segments += points[i] == points[i - 1] ? 0 : 1;
    if (segments > finished) break;
    ++cut;
  }
  const auto stored = job["stroke"].get<size_t>();
  EXPECT_GE(cut, 6U);
  EXPECT_LE(stored, cut) << "never ahead of the cut";
  EXPECT_GE(stored + 3, cut) << "no more than a few strokes behind: stored " << stored << ", cut " << cut;
}

const fs::path& oneSheet();  // (below: a planned folder of one sheet)

// A webhook's receiver: an HTTP server on a loopback port that keeps the
// body of each request and answers 204, as a phone's push relay would.
class WebhookReceiver {
 public:
  WebhookReceiver() {
    listener_ = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ::bind(listener_, reinterpret_cast<sockaddr*>(&address), sizeof address);
    ::listen(listener_, 8);
    socklen_t size = sizeof address;
    ::getsockname(listener_, reinterpret_cast<sockaddr*>(&address), &size);
    port_ = ntohs(address.sin_port);
    thread_ = std::thread([this] { serve(); });
  }
  ~WebhookReceiver() {
    stopping_ = true;
    thread_.join();
    ::close(listener_);
  }
  WebhookReceiver(const WebhookReceiver&) = delete;
  WebhookReceiver& operator=(const WebhookReceiver&) = delete;
  [[nodiscard]] int port() const { return port_; }
  [[nodiscard]] std::vector<json> events() const {
    std::lock_guard lock(mutex_);
    return events_;
  }

 private:
  void serve() {
    while (!stopping_) {
      pollfd ready{listener_, POLLIN, 0};
      if (::poll(&ready, 1, 100) <= 0) continue;
      const int client = ::accept(listener_, nullptr, nullptr);
      if (client < 0) continue;
      std::string request;
      char buffer[4096];
      for (;;) {
        const size_t header = request.find("\r\n\r\n");
        if (header != std::string::npos) {
          const size_t length = request.find("Content-Length: ");
          const size_t body = length == std::string::npos ? 0 : std::stoul(request.substr(length + 16));
          if (request.size() >= header + 4 + body) {
            std::lock_guard lock(mutex_);
            events_.push_back(json::parse(request.substr(header + 4, body), nullptr, false));
            break;
          }
        }
        const ssize_t got = ::read(client, buffer, sizeof buffer);
        if (got <= 0) break;
        request.append(buffer, static_cast<size_t>(got));
      }
      const std::string reply = "HTTP/1.1 204 No Content\r\nContent-Length: 0\r\nConnection: close\r\n\r\n";
      (void)!::write(client, reply.data(), reply.size());
      ::close(client);
    }
  }
  int listener_ = -1, port_ = 0;
  std::atomic<bool> stopping_{false};
  mutable std::mutex mutex_;
  std::vector<json> events_;
  std::thread thread_;
};

// The events of a job reach a webhook and, through a real broker (Debian's
// mosquitto, started here), an MQTT subscriber: the next sheet to load, and
// the job's end.
TEST(Daemon, TheOperatorsEventsReachAWebhookAndAnMqttBroker) {
  TempDir root;
  const int broker = freePort();
  std::ofstream(root.path() / "mosquitto.conf")
      << fmt::format("listener {} 127.0.0.1\nallow_anonymous true\npersistence false\npid_file {}\nuser root\n", broker,
                     (root.path() / "mosquitto.pid").string());
  ASSERT_EQ(run("mosquitto -d -c " + quoted(root.path() / "mosquitto.conf")).status, 0);
  struct StopBroker {
    fs::path pid;
    ~StopBroker() { run("kill $(cat " + quoted(pid) + ")"); }
  } stopBroker{root.path() / "mosquitto.pid"};
  const fs::path heard = root.path() / "mqtt";
  ASSERT_TRUE(eventually([&] { return fs::exists(root.path() / "mosquitto.pid"); }, 10));
  run(fmt::format("(timeout 120 mosquitto_sub -h 127.0.0.1 -p {} -t 'lab/lasers/#' -v -C 3 > {} 2>&1 &)", broker,
                  quoted(heard)));
  WebhookReceiver webhook;
  Daemon daemon(root.path(),
                fmt::format("devices: [{{name: laser1, machine: grbl-diode-400, uri: \"sim:grbl?speed=400\"}}]\n"
                            "notify:\n  webhooks: [http://127.0.0.1:{}/rotafab]\n  mqtt: mqtt://127.0.0.1:{}\n"
                            "  topic: lab/lasers\n",
                            webhook.port(), broker));
  daemon.start();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // (the subscriber connected)
  const long long id = daemon.clientJson("submit " + quoted(threeSheets()))["id"];
  ASSERT_EQ(state(daemon.waitForJob(id, [](const json& j) { return state(j) == "ready"; })), "ready");
  ASSERT_EQ(daemon.client(fmt::format("start {}", id)).status, 0);
  ASSERT_TRUE(daemon
                  .waitForJob(
                      id, [](const json& j) { return j.value("waiting_for_next", false); }, 120)
                  .value("waiting_for_next", false));
  ASSERT_TRUE(eventually([&] { return webhook.events().size() >= 1; }, 10));
  const json load = webhook.events().front();
  EXPECT_EQ(load["event"], "load_sheet") << load.dump();
  EXPECT_EQ(load["job"], id);
  EXPECT_EQ(load["waiting_sheet"], 2);
  EXPECT_EQ(load["waiting_for"], "sheet 2 to be loaded");
  EXPECT_EQ(load["sheets_cut"], 1);
  EXPECT_TRUE(load.value("stock", "").starts_with("posterboard (0.8 mm)")) << load.dump();
  ASSERT_EQ(daemon.client(fmt::format("cancel {}", id)).status, 0);
  ASSERT_TRUE(eventually([&] { return webhook.events().size() >= 2; }, 10));
  EXPECT_EQ(webhook.events()[1]["event"], "job_cancelled") << webhook.events()[1].dump();
  // A one-sheet job cut to its end.
  const long long one = daemon.clientJson("submit " + quoted(oneSheet()))["id"];
  ASSERT_EQ(state(daemon.waitForJob(one, [](const json& j) { return state(j) == "ready"; })), "ready");
  ASSERT_EQ(daemon.client(fmt::format("start {}", one)).status, 0);
  ASSERT_TRUE(eventually([&] { return webhook.events().size() >= 3; }, 60));
  EXPECT_EQ(webhook.events()[2]["event"], "job_done") << webhook.events()[2].dump();
  EXPECT_EQ(webhook.events()[2]["job"], one);
  // The same events, in order, on the broker's topic.
  ASSERT_TRUE(eventually(
      [&] {
        const std::string lines = readFile(heard);
        return std::count(lines.begin(), lines.end(), '\n') >= 3;
      },
      10))
      << readFile(heard);
  const std::string said = readFile(heard);
  const size_t a = said.find("lab/lasers/load_sheet {"), b = said.find("lab/lasers/job_cancelled {"),
               c = said.find("lab/lasers/job_done {");
  EXPECT_NE(a, std::string::npos) << said;
  EXPECT_LT(a, b) << said;
  EXPECT_LT(b, c) << said;
  EXPECT_NE(said.find(fmt::format("\"job\":{}", one)), std::string::npos) << said;
}

// A receiver that is not there holds up nothing: the job is cut, and the log says so once.
TEST(Daemon, AnAbsentReceiverHoldsUpNothingAndIsLoggedOnce) {
  TempDir root;
  Daemon daemon(root.path(),
                fmt::format("devices: [{{name: laser1, machine: grbl-diode-400, uri: \"sim:grbl?speed=400\"}}]\n"
                            "notify: {{webhooks: [http://127.0.0.1:{}/], mqtt: mqtt://127.0.0.1:{}}}\n",
                            freePort(), freePort()));
  daemon.start();
  for (int i = 0; i < 2; ++i) {
    const long long id = daemon.clientJson("submit " + quoted(oneSheet()))["id"];
    ASSERT_EQ(state(daemon.waitForJob(id, [](const json& j) { return state(j) == "ready"; })), "ready");
    ASSERT_EQ(daemon.client(fmt::format("start {}", id)).status, 0);
    ASSERT_EQ(state(daemon.waitForJob(
                  id, [](const json& j) { return state(j) == "done"; }, 60)),
              "done");
  }
  ASSERT_TRUE(eventually([&] { return readFile(daemon.log()).find("mqtt://") != std::string::npos; }, 15));
  const std::string log = readFile(daemon.log());
  size_t webhookLines = 0;
  for (size_t at = log.find("notifications: http://"); at != std::string::npos;
       at = log.find("notifications: http://", at + 1)) {
    ++webhookLines;
  }
  EXPECT_EQ(webhookLines, 1U) << log;
}

// `clients` clients at once, each submitting `each` jobs through the daemon
// `through` gives it, with the words `words` gives each submission (its
// number); the jobs' numbers, and what any refusal said.
std::vector<long long> submitAtOnce(int clients, int each, const std::function<const Daemon&(int client)>& through,
                                    const std::function<std::string(int submission)>& words,
                                    std::vector<std::string>& failures) {
  std::vector<std::thread> threads;
  std::mutex mutex;
  std::vector<long long> ids;
  for (int c = 0; c < clients; ++c) {
    threads.emplace_back([&, c] {
      for (int i = 0; i < each; ++i) {
        const CommandResult r = through(c).client(words(c * each + i));
        std::lock_guard lock(mutex);
        if (r.status != 0) {
          failures.push_back(r.err);
          continue;
        }
        ids.push_back(json::parse(r.out)["id"].get<long long>());
      }
    });
  }
  for (auto& thread : threads) thread.join();
  return ids;
}

TEST(Daemon, TwoHundredConcurrentSubmissionsEachLandExactlyOnce) {
  TempDir root;
  Daemon daemon(root.path());
  daemon.start();
  constexpr int kClients = 8, kEach = 25;
  std::vector<std::string> failures;
  // (The priority tells each submission apart.)
  const std::vector<long long> ids = submitAtOnce(
      kClients, kEach, [&](int) -> const Daemon& { return daemon; },
      [&](int tag) { return fmt::format("submit {} --priority {} --json", quoted(threeSheets()), tag); }, failures);
  EXPECT_TRUE(failures.empty()) << failures.front();
  EXPECT_EQ(std::set<long long>(ids.begin(), ids.end()).size(), static_cast<size_t>(kClients * kEach));
  const json jobs = daemon.clientJson("jobs")["jobs"];
  ASSERT_EQ(jobs.size(), static_cast<size_t>(kClients * kEach));
  std::multiset<int> priorities;
  for (const json& job : jobs) priorities.insert(job["priority"].get<int>());
  for (int tag = 0; tag < kClients * kEach; ++tag) EXPECT_EQ(priorities.count(tag), 1u) << tag;
  // In queue order: the highest priority first.
  EXPECT_EQ(jobs.front()["priority"], kClients * kEach - 1);
  for (const json& job : jobs) EXPECT_EQ(job["state"], "ready") << job.dump();
}

TEST(Daemon, APlannedFolderIsReadyWhenSubmittedAndOneWithABrokenSheetIsRefusedNamingIt) {
  TempDir root;
  Daemon daemon(root.path());
  daemon.start();
  // Its sheets are read and checked against the device's bed as it is submitted: ready at once,
  // its queued, planning and ready recorded together.
  const CommandResult submitted = daemon.client("submit " + quoted(threeSheets()));
  ASSERT_EQ(submitted.status, 0) << submitted.err;
  EXPECT_NE(submitted.out.find("job 1: ready: planned: 3 sheets; start it with `rotafab start 1`"), std::string::npos)
      << submitted.out;
  const json job = daemon.clientJson("status 1");
  EXPECT_EQ(job["state"], "ready");
  EXPECT_EQ(job["device"], "laser1");
  EXPECT_EQ(job["sheets"], 3);
  // What the queue shows of the plan, from the manifest as the fast reader lists it.
  EXPECT_EQ(job["summary"]["sheets"], 3);
  EXPECT_GT(job["summary"]["panels"].get<int>(), 0);
  EXPECT_EQ(job["summary"]["cost"]["sheets"], 3);
  std::vector<std::string> states;
  for (const json& t : job["transitions"]) states.push_back(t["to"]);
  EXPECT_EQ(states, (std::vector<std::string>{"queued", "planning", "ready"}));
  // A sheet that is not an SVG: one line naming it as the submitter knows it, and no job.
  const fs::path broken = root.path() / "broken";
  fs::copy(threeSheets(), broken);
  std::string sheet;
  for (const auto& entry : fs::directory_iterator(broken)) {
    const std::string name = entry.path().filename().string();
    if (name.ends_with(".svg") && !name.ends_with(".preview.svg")) sheet = entry.path().string();
  }
  ASSERT_FALSE(sheet.empty());
  { std::ofstream(sheet, std::ios::trunc) << "<svg"; }
  const CommandResult refused =
      daemon.client("submit " + quoted(fs::path(broken.string() + "/")));  // (as a shell completes it)
  EXPECT_EQ(refused.status, 1);
  EXPECT_EQ(std::count(refused.err.begin(), refused.err.end(), '\n'), 1) << refused.err;
  EXPECT_NE(refused.err.find(sheet), std::string::npos) << refused.err;
  // A manifest cut short: the full reader's words (the fast one gives up), naming it, and no job.
  const fs::path cutShort = root.path() / "cut-short";
  fs::copy(threeSheets(), cutShort);
  {
    const std::string text = readFile(cutShort / "manifest.json");
    std::ofstream(cutShort / "manifest.json", std::ios::trunc) << text.substr(0, text.size() / 2);
  }
  const CommandResult notJson = daemon.client("submit " + quoted(cutShort));
  EXPECT_EQ(notJson.status, 1);
  EXPECT_EQ(std::count(notJson.err.begin(), notJson.err.end(), '\n'), 1) << notJson.err;
  EXPECT_NE(notJson.err.find((cutShort / "manifest.json").string() + ": not JSON"), std::string::npos) << notJson.err;
  EXPECT_EQ(daemon.clientJson("jobs")["jobs"].size(), 1u);
  size_t entries = 0;
  for (const auto& entry : fs::directory_iterator(daemon.stateDir() / "spool")) entries += entry.is_directory() ? 1 : 0;
  EXPECT_EQ(entries, 1u);
}

TEST(Daemon, HostileRequestsAreRefusedWhileOtherClientsAreServed) {
  TempDir root;
  const std::string token = "s3cret-token";
  Daemon daemon(root.path(),
                fmt::format("upload_limit: 100000\nheader_timeout: 1\n"
                            "listen: [unix:{}, tcp://127.0.0.1:0]\n"
                            "tokens: [{{name: alice, hash: \"{}\"}}]\n",
                            (root.path() / "run/rotafab/rotafabd.sock").string(), service::hashToken(token, "5a17")));
  daemon.start();
  // A slow client holds a connection open with half a header...
  const int slow = connectUnix(daemon.socket());
  ASSERT_GE(slow, 0);
  ::send(slow, "GET /api/jobs HTTP/1.1\r\nHost: x\r\n", 33, MSG_NOSIGNAL);
  // ...while the others are refused, each in its own words, and the daemon goes on.
  const auto refused = [&](const RawReply& reply, int status, const std::string& words) {
    EXPECT_EQ(reply.status, status) << reply.text;
    ASSERT_TRUE(reply.body.is_object()) << reply.text;
    EXPECT_NE(reply.body.value("error", "").find(words), std::string::npos) << reply.text;
  };
  refused(daemon.post("/api/jobs", "{not json"), 400, "not valid JSON");
  refused(daemon.raw("\x01\x02\x03 garbage \xff\r\n\r\n"), 400, "malformed request");
  refused(daemon.raw("GET /api/jobs HTTP/1.1\r\nHost: x\r\nX-Flood: " + std::string(40000, 'a') + "\r\n\r\n"), 431,
          "larger than 16384 bytes");
  refused(daemon.raw("POST /api/jobs HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\nContent-Length: "
                     "5000000\r\n\r\n{}"),
          413, "POST /api/jobs takes at most 65536");
  refused(daemon.raw("POST /api/jobs HTTP/1.1\r\nHost: x\r\nContent-Type: multipart/form-data; boundary=b\r\n"
                     "Content-Length: 5000000\r\n\r\n--b"),
          413, "takes at most 100000");
  refused(daemon.get("/api/nothing"), 404, "no such resource");
  refused(daemon.raw("DELETE /api/jobs HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n"), 405, "GET and POST");
  refused(daemon.post("/api/jobs", R"({"path": "relative/cube.obj"})"), 400, "expected an absolute path");
  refused(daemon.post("/api/jobs", R"({"path": "/nowhere/cube.obj"})"), 400, "no such file or folder");
  refused(daemon.post("/api/jobs/1/start", "{}"), 404, "there is no job 1");
  refused(daemon.post("/api/jobs/1/explode", "{}"), 404, "no action explode");
  // The make options are read by `make`'s own table.
  const std::string form =
      "--b\r\nContent-Disposition: form-data; "
      "name=\"options\"\r\n\r\n[\"--structure\",\"band\",\"--samples\",\"999\"]\r\n"
      "--b\r\nContent-Disposition: form-data; name=\"file\"; filename=\"cube.obj\"\r\n\r\nv 0 0 0\r\n--b--\r\n";
  refused(daemon.raw(fmt::format("POST /api/jobs HTTP/1.1\r\nHost: x\r\nContent-Type: multipart/form-data; "
                                 "boundary=b\r\nContent-Length: {}\r\n\r\n{}",
                                 form.size(), form)),
          400, "make options: --samples: Value 999 not in range 1 to 64");
  // Served meanwhile.
  EXPECT_EQ(daemon.get("/api/jobs").status, 200);
  // The slow client's connection is closed once its header's time is up.
  EXPECT_EQ(exchange(slow, "", 5), "");
  ::close(slow);
  // TCP: the token is asked for, and only the right one lets anyone in.
  const json where = json::parse(readFile(daemon.stateDir() / "rotafabd.json"));
  std::string tcp;
  for (const json& address : where["listen"]) {
    if (address.get<std::string>().starts_with("tcp://")) tcp = "http://" + address.get<std::string>().substr(6);
  }
  ASSERT_FALSE(tcp.empty()) << where.dump();
  const CommandResult none = daemon.client("jobs --server " + tcp);
  EXPECT_EQ(none.status, 1);
  EXPECT_NE(none.err.find("this listener needs a token"), std::string::npos) << none.err;
  const CommandResult wrong = daemon.client("jobs --server " + tcp + " --token guess");
  EXPECT_EQ(wrong.status, 1);
  EXPECT_NE(wrong.err.find("not one this daemon knows"), std::string::npos) << wrong.err;
  // A folder on the daemon's machine is for its local users; over TCP a mesh is uploaded.
  const CommandResult folder =
      daemon.client("submit " + quoted(threeSheets()) + " --server " + tcp + " --token " + token);
  EXPECT_EQ(folder.status, 1);
  EXPECT_NE(folder.err.find("over its Unix socket only"), std::string::npos) << folder.err;
  const CommandResult right = daemon.client("submit " + quoted(kSource / "examples/cube.obj") +
                                            " --structure band --server " + tcp + " --token " + token);
  EXPECT_EQ(right.status, 0) << right.err;
  // A job submitted with a token belongs to the token's holder.
  EXPECT_EQ(daemon.job(1)["owner"], "alice");
}

TEST(Daemon, AFullSpoolDiskRefusesTheSubmissionAndLosesNoEarlierJob) {
  TempDir root;
  Daemon daemon(root.path());
  const fs::path spool = daemon.stateDir() / "spool";
  fs::create_directories(spool);
  if (::mount("tmpfs", spool.c_str(), "tmpfs", 0, "size=6m") != 0) {
    GTEST_SKIP() << "mounting a small tmpfs needs root (CI runs as root)";
  }
  struct Unmount {
    fs::path at;
    ~Unmount() { ::umount2(at.c_str(), MNT_DETACH); }
  } unmount{spool};
  daemon.start();
  ASSERT_EQ(daemon.client("submit " + quoted(threeSheets())).status, 0);
  // A mesh of 8 MB: a cube and a long comment.
  const fs::path big =
      root.write("big.obj", readFile(kSource / "examples/cube.obj") + "# " + std::string(8 << 20, 'x') + "\n");
  const CommandResult full = daemon.client("submit " + quoted(big) + " --structure band");
  EXPECT_EQ(full.status, 1);
  EXPECT_NE(full.err.find("the spool's disk is full; the job was not accepted"), std::string::npos) << full.err;
  const json jobs = daemon.clientJson("jobs")["jobs"];
  ASSERT_EQ(jobs.size(), 1u);
  EXPECT_EQ(jobs[0]["kind"], "planned");
  // Nothing half-written stays in the spool: the one job's folder only.
  size_t entries = 0;
  for (const auto& entry : fs::directory_iterator(spool)) entries += entry.is_directory() ? 1 : 0;
  EXPECT_EQ(entries, 1u);
  daemon.kill9();
}

TEST(Daemon, ADeviceFaultFailsOnlyItsJobWithTheDevicesOwnMessage) {
  TempDir root;
  Daemon daemon(root.path(),
                "devices:\n"
                "  - {name: faulty, machine: grbl-diode-400, uri: \"sim:grbl?speed=50&fault=alarm&after=30\"}\n"
                "  - {name: good, machine: grbl-diode-400, uri: \"sim:grbl?speed=200\"}\n");
  daemon.start();
  const long long bad = daemon.clientJson("submit " + quoted(threeSheets()) + " --device faulty")["id"];
  const long long good = daemon.clientJson("submit " + quoted(threeSheets()) + " --device good")["id"];
  for (long long id : {bad, good}) {
    ASSERT_EQ(state(daemon.waitForJob(id, [](const json& j) { return state(j) == "ready"; })), "ready");
    const CommandResult started = daemon.client(fmt::format("start {}", id));
    ASSERT_EQ(started.status, 0) << started.err;
  }
  const json failed = daemon.waitForJob(bad, [](const json& j) { return state(j) == "failed"; });
  EXPECT_EQ(state(failed), "failed") << failed.dump();
  EXPECT_NE(failed.value("message", "").find("ALARM:1"), std::string::npos) << failed.dump();
  EXPECT_TRUE(failed.value("message", "").find("once it is fixed, load sheet 1 and resume from it") !=
                  std::string::npos ||
              failed.value("message", "").find("once it is fixed, leave sheet 1 where it is and resume from it") !=
                  std::string::npos)
      << failed.dump();
  for (int sheet = 2; sheet <= 3; ++sheet) {
    const json waiting = daemon.waitForJob(
        good, [](const json& j) { return j.value("waiting_for_next", false); }, 120);
    ASSERT_TRUE(waiting.value("waiting_for_next", false)) << waiting.dump();
    ASSERT_EQ(daemon.client(fmt::format("next {}", good)).status, 0);
  }
  EXPECT_EQ(state(daemon.waitForJob(
                good, [](const json& j) { return state(j) == "done"; }, 120)),
            "done");
  const json devices = daemon.clientJson("devices --daemon")["devices"];
  EXPECT_EQ(devices[0]["state"], "fault");
  EXPECT_NE(devices[0].value("message", "").find("ALARM:1"), std::string::npos) << devices.dump();
  EXPECT_EQ(devices[1]["state"], "idle");
}

// The daemon drives every kind of controller alike: a K40's M2 Nano over
// USB and a CO2 laser's Ruida over UDP, each planned for its own machine.
TEST(Daemon, AJobIsPlannedForAndCutOnASimulatedM2NanoAndASimulatedRuida) {
  TempDir root;
  Daemon daemon(root.path(),
                "devices: [{name: k40, machine: k40-m2nano, uri: \"sim:m2nano?speed=50\"}, "
                "{name: co2, machine: ruida-co2-60w, uri: \"sim:ruida?speed=200\"}]\n");
  daemon.start();
  for (const auto& [device, machine, identity] :
       {std::tuple{"k40", "k40-m2nano", "Lihuiyu M2 Nano"}, std::tuple{"co2", "ruida-co2-60w", "Ruida controller"}}) {
    SCOPED_TRACE(device);
    const long long id = daemon.clientJson("submit " + quoted(kSource / "examples/cube.obj") +
                                           " --structure band --time 0 --device " + device)["id"];
    const json ready = daemon.waitForJob(id, [](const json& j) { return state(j) == "ready" || state(j) == "failed"; });
    ASSERT_EQ(state(ready), "ready") << ready.dump();
    EXPECT_NE(ready["transitions"][1]["reason"].get<std::string>().find(machine), std::string::npos);
    ASSERT_EQ(daemon.client(fmt::format("start {}", id)).status, 0);
    const json done = daemon.waitForJob(
        id, [](const json& j) { return state(j) == "done" || state(j) == "failed"; }, 120);
    EXPECT_EQ(state(done), "done") << done.dump();
    int seen = 0;
    const json listed =
        daemon.clientJson("devices --daemon");  // (a temporary's member would not outlive the loop's start)
    for (const json& d : listed["devices"]) {
      if (d["name"] == device) {
        ++seen;
        EXPECT_NE(d.value("checked", "").find(identity), std::string::npos) << d.dump();
      }
    }
    EXPECT_EQ(seen, 1);
  }
}

TEST(Daemon, APlanLongerThanPlanTimeoutIsStoppedAndItsJobFailsSayingSo) {
  TempDir root;
  Daemon daemon(root.path(), "plan_timeout: 1\n");
  daemon.start();
  // The bunny's default plan takes minutes on these machines.
  const long long id =
      daemon.clientJson("submit " + quoted(kSource / "examples/bunny.obj") + " --structure band")["id"];
  const auto started = std::chrono::steady_clock::now();
  const json failed = daemon.waitForJob(
      id, [](const json& j) { return state(j) == "failed" || state(j) == "ready"; }, 60);
  EXPECT_EQ(state(failed), "failed") << failed.dump();
  EXPECT_NE(failed.value("message", "").find("longer than plan_timeout (1 s)"), std::string::npos) << failed.dump();
  EXPECT_LT(std::chrono::steady_clock::now() - started, std::chrono::seconds(30));
  // The planner is free again: the next job's plan begins (under the same 1 s limit, whatever its end).
  const long long next =
      daemon.clientJson("submit " + quoted(kSource / "examples/cube.obj") + " --structure band --time 0")["id"];
  EXPECT_NE(state(daemon.waitForJob(next, [](const json& j) { return state(j) != "queued"; })), "queued");
}

TEST(Daemon, AStartWhileItsDeviceIsStillCheckedWaitsInTheClientForTheCheck) {
  TempDir root;
  // Each reply a second late: the check at the daemon's start (connect, stop, laser off) takes seconds.
  Daemon daemon(root.path(), "devices: [{name: laser1, machine: grbl-diode-400, uri: \"sim:grbl?latency=1000\"}]\n");
  const fs::path folder = threeSheets();  // (made before the daemon starts its check)
  daemon.start();
  ASSERT_EQ(daemon.post("/api/jobs", json{{"path", folder.string()}}.dump()).status, 201);
  ASSERT_EQ(daemon.get("/api/devices").body["devices"][0]["state"], "checking");
  // The daemon refuses at once, saying when to ask again: a start held in the daemon
  // would begin a cut after its operator had perhaps given up on it.
  const RawReply refused = daemon.post("/api/jobs/1/start", "{}");
  EXPECT_EQ(refused.status, 409);
  EXPECT_NE(refused.body.value("error", "").find("laser1 is still being checked"), std::string::npos) << refused.text;
  EXPECT_TRUE(refused.body["retry_after"].is_number()) << refused.text;
  // The client waits (Ctrl-C gives up), then starts it.
  const CommandResult started = daemon.client("start 1");
  EXPECT_EQ(started.status, 0) << started.err;
  EXPECT_NE(started.err.find("waiting for the daemon's check of laser1"), std::string::npos) << started.err;
  EXPECT_EQ(state(daemon.job(1)), "running");
  EXPECT_NE(daemon.get("/api/devices").body["devices"][0].value("checked", "").find("stopped"), std::string::npos);
}

TEST(Daemon, OneDaemonPerStateDirectoryAndAConfigMistakeIsOneLine) {
  TempDir root;
  Daemon daemon(root.path());
  daemon.start();
  const int second = daemon.runToEnd({});
  EXPECT_EQ(second, 1);
  EXPECT_NE(readFile(daemon.log()).find("another rotafabd (pid "), std::string::npos) << readFile(daemon.log());
  const fs::path bad = root.write("bad.yaml", "state_dir: " + (root.path() / "other").string() +
                                                  "\ndevices:\n  - {name: laser1, uri: \"sim:grbl\", machine: nope}\n");
  EXPECT_EQ(daemon.runToEnd({"--config", bad.string()}), 1);
  EXPECT_NE(readFile(daemon.log()).find("device laser1: no machine profile named 'nope'"), std::string::npos)
      << readFile(daemon.log());
  // Still serving.
  EXPECT_EQ(daemon.get("/api").status, 200);
}

// `store: postgresql://...`: the same daemon on a PostgreSQL server. A job
// is planned and cut, a kill mid-cut leaves it interrupted (resumed only by
// an operator), and a second daemon under the same host name is refused in one line.
TEST(Daemon, OnAPostgresStoreAKillMidCutLeavesTheJobInterruptedAndASecondDaemonIsRefused) {
  test::TestDatabase database;
  TempDir root, otherRoot;
  const std::string config = "store: " + database.uri() +
                             "\nhost: solo\nlease: 2\ndevices: [{name: laser1, machine: grbl-diode-400, uri: "
                             "\"sim:grbl?speed=5\"}]\n";
  Daemon daemon(root.path(), config);
  daemon.start();
  const long long id = cuttingThreeSheets(daemon);
  ASSERT_NE(id, 0);

  Daemon second(otherRoot.path(), config);
  EXPECT_EQ(second.runToEnd({"--config", (otherRoot.path() / "rotafabd.yaml").string()}), 1);
  EXPECT_NE(readFile(second.log()).find(": another rotafabd runs as host solo on this job store"), std::string::npos)
      << readFile(second.log());

  daemon.kill9();
  daemon.start();
  const json job = daemon.job(id);
  EXPECT_EQ(state(job), "interrupted") << job.dump();
  EXPECT_NE(job.value("message", "").find("the daemon stopped while it cut"), std::string::npos) << job.dump();
  // The store agrees with itself: every job in one state, every transition recorded once.
  EXPECT_EQ(service::openPostgresStore(database.uri())->integrityCheck(), "ok");
  std::vector<std::string> states;
  for (const json& t : job["transitions"]) states.push_back(t["to"]);
  EXPECT_EQ(states, (std::vector<std::string>{"queued", "planning", "ready", "running", "interrupted"}));
}

// A `make` output folder of one sheet, quick to cut.
const fs::path& oneSheet() {
  static const fs::path made = plannedExample("cube.obj");
  return made;
}

// One host of a fab lab: its name, the shared store and spool, a lease
// (short, 3 s, where a test waits for one to lapse), and one simulated GRBL
// of its own.
std::string hostConfig(const test::TestDatabase& database, const fs::path& spool, const std::string& host,
                       const std::string& simulator, bool autoStart, int leaseSeconds = 3) {
  return fmt::format(
      "store: {}\nhost: {}\nspool: {}\nlease: {}\ndevices: [{{name: laser-{}, machine: grbl-diode-400, uri: "
      "\"{}\", auto_start: {}}}]\n",
      database.uri(), host, spool.string(), leaseSeconds, host, simulator, autoStart);
}

std::vector<std::string> statesOf(const json& job) {
  std::vector<std::string> states;
  for (const json& t : job["transitions"]) states.push_back(t["to"]);
  return states;
}

// Two hosts on one PostgreSQL store and one spool, each with its own
// cutter: 200 submissions through either host at once each land once and
// are cut exactly once, on one device or the other.
TEST(Daemon, TwoHostsOnOneStoreCutEachOfTwoHundredConcurrentSubmissionsExactlyOnce) {
  test::TestDatabase database;
  TempDir shared, rootA, rootB;
  // (No lease lapses here: one long enough that 200 submissions on two busy cores do not stall its renewal.)
  constexpr int kLeaseSeconds = 15;
  Daemon a(rootA.path(), hostConfig(database, shared.path(), "a", "sim:grbl?speed=10000", true, kLeaseSeconds));
  Daemon b(rootB.path(), hostConfig(database, shared.path(), "b", "sim:grbl?speed=10000", true, kLeaseSeconds));
  a.start();
  b.start();
  constexpr int kClients = 8, kEach = 25;
  std::vector<std::string> failures;
  const std::vector<long long> ids = submitAtOnce(
      kClients, kEach, [&](int client) -> const Daemon& { return client % 2 == 0 ? a : b; },
      [&](int) { return "submit " + quoted(oneSheet()) + " --json"; }, failures);
  ASSERT_TRUE(failures.empty()) << failures.front();
  ASSERT_EQ(std::set<long long>(ids.begin(), ids.end()).size(), static_cast<size_t>(kClients * kEach));
  json jobs;
  const bool allDone = eventually(
      [&] {
        jobs = b.clientJson("jobs")["jobs"];
        return std::all_of(jobs.begin(), jobs.end(), [](const json& job) { return state(job) == "done"; });
      },
      300);
  ASSERT_TRUE(allDone) << jobs.dump();
  ASSERT_EQ(jobs.size(), static_cast<size_t>(kClients * kEach));
  std::map<std::string, int> cutOn;
  for (const json& job : jobs) ++cutOn[job["device"].get<std::string>()];
  EXPECT_GT(cutOn["laser-a"], 0);
  EXPECT_GT(cutOn["laser-b"], 0);
  EXPECT_EQ(cutOn["laser-a"] + cutOn["laser-b"], kClients * kEach);
  // Each cut once: one run, then done, in every job's history.
  for (const long long id : {ids.front(), ids[ids.size() / 2], ids.back()}) {
    EXPECT_EQ(statesOf(a.job(id)), (std::vector<std::string>{"queued", "planning", "ready", "running", "done"}));
  }
  auto store = service::openPostgresStore(database.uri());
  for (const service::JobRecord& job : store->jobs()) {
    const auto history = store->transitions(job.id);
    EXPECT_EQ(std::count_if(history.begin(), history.end(),
                            [](const service::Transition& t) { return t.to == service::JobState::Running; }),
              1)
        << job.id;
  }
  EXPECT_EQ(store->integrityCheck(), "ok");
}

// Three hosts; two are killed (kill -9), one mid-cut and one mid-plan. Once
// their leases run out the third releases their jobs: the cut comes back
// interrupted and stays so (no laser restarts by itself), the plan is made
// again on the third, which cuts it and goes on with its own job; the
// client shows the hosts that are gone.
TEST(Daemon, WhenTwoOfThreeHostsAreKilledTheirCutIsInterruptedTheirPlanMadeAgainAndTheThirdGoesOn) {
  test::TestDatabase database;
  TempDir shared, rootA, rootB, rootC;
  Daemon a(rootA.path(), hostConfig(database, shared.path(), "a", "sim:grbl?speed=2", true));
  Daemon c(rootC.path(), hostConfig(database, shared.path(), "c", "sim:grbl?speed=2", false));
  a.start();
  c.start();
  // X: cut on a's laser. Y: a mesh for any device, planned on a or c (a nest of 8 s).
  const long long x = a.clientJson("submit " + quoted(oneSheet()) + " --device laser-a --json")["id"];
  const json cutting =
      a.waitForJob(x, [](const json& j) { return j.contains("progress") && j["progress"]["stroke"] >= 3; });
  ASSERT_EQ(state(cutting), "running") << cutting.dump();
  EXPECT_EQ(cutting["host"], "a");
  const long long y = c.clientJson("submit " + quoted(kSource / "examples/soccer-ball.obj") +
                                   " --structure band --time 12 --json")["id"];
  const json planning = c.waitForJob(y, [](const json& j) { return state(j) == "planning"; });
  ASSERT_EQ(state(planning), "planning") << planning.dump();
  const std::string planner = planning["host"];
  Daemon b(rootB.path(), hostConfig(database, shared.path(), "b", "sim:grbl?speed=100", true));
  b.start();
  // Z: b's own.
  const long long z = b.clientJson("submit " + quoted(oneSheet()) + " --device laser-b --json")["id"];
  a.kill9();
  c.kill9();
  const json interrupted = b.waitForJob(
      x, [](const json& j) { return state(j) == "interrupted"; }, 30);
  EXPECT_EQ(state(interrupted), "interrupted") << interrupted.dump();
  EXPECT_NE(interrupted.value("message", "").find("host a (its last heartbeat "), std::string::npos)
      << interrupted.dump();
  EXPECT_NE(interrupted.value("message", "").find("stopped while it cut, at sheet 1 of 1"), std::string::npos)
      << interrupted.dump();
  EXPECT_EQ(state(b.waitForJob(z, [](const json& j) { return state(j) == "done"; })), "done");
  // (Cut on laser-b, its first sheet; it would then wait for the next to be loaded.)
  const json replanned = b.waitForJob(
      y, [](const json& j) { return state(j) == "running"; }, 120);
  ASSERT_EQ(state(replanned), "running") << replanned.dump();
  EXPECT_EQ(replanned["device"], "laser-b");
  EXPECT_EQ(replanned["host"], "b");
  // Planned, released, planned again (more than once if b's own plan was
  // stopped too, as b's lease watchdog does when a loaded machine delays
  // its heartbeat), then ready and cut; never interrupted.
  const std::vector<std::string> history = statesOf(replanned);
  ASSERT_GE(history.size(), 6u) << replanned.dump();
  EXPECT_EQ(std::vector<std::string>(history.begin(), history.begin() + 3),
            (std::vector<std::string>{"queued", "planning", "queued"}));
  EXPECT_EQ(std::vector<std::string>(history.end() - 3, history.end()),
            (std::vector<std::string>{"planning", "ready", "running"}));
  EXPECT_NE(replanned["transitions"][2]["reason"].get<std::string>().find("host " + planner), std::string::npos)
      << replanned.dump();
  // Nothing restarted the interrupted cut.
  EXPECT_EQ(state(b.job(x)), "interrupted");
  EXPECT_EQ(statesOf(b.job(x)), (std::vector<std::string>{"queued", "planning", "ready", "running", "interrupted"}));
  // The client shows who is gone.
  const CommandResult devices = b.client("devices --daemon");
  EXPECT_NE(devices.out.find("laser-a     a             gone"), std::string::npos) << devices.out;
  EXPECT_NE(devices.out.find("a (gone, last heard "), std::string::npos) << devices.out;
  EXPECT_NE(devices.out.find("b (up"), std::string::npos) << devices.out;
  // Its job is started only where its device is.
  const CommandResult elsewhere = b.client(fmt::format("resume {} --from-sheet 1", x));
  EXPECT_EQ(elsewhere.status, 1);
  EXPECT_NE(elsewhere.err.find("a device of host a"), std::string::npos) << elsewhere.err;
  EXPECT_EQ(service::openPostgresStore(database.uri())->integrityCheck(), "ok");
}

// Two hosts on one store; a job submitted through b, cut on a's slow laser
// (its laser's changes in `witness`).
struct TwoHostsOneCutting {
  test::TestDatabase database;
  TempDir shared, rootA, rootB;
  fs::path witness = rootA.path() / "laser";
  Daemon a{rootA.path(),
           hostConfig(database, shared.path(), "a", "sim:grbl?speed=2&witness=" + witness.string(), true)};
  Daemon b{rootB.path(), hostConfig(database, shared.path(), "b", "sim:grbl?speed=100", false)};
  long long id = 0;
  // Starts both and the cut; whether it got to its third stroke.
  bool cutting() {
    a.start();
    b.start();
    id = b.clientJson("submit " + quoted(oneSheet()) + " --device laser-a --json")["id"];
    const json job =
        a.waitForJob(id, [](const json& j) { return j.contains("progress") && j["progress"]["stroke"] >= 3; });
    EXPECT_EQ(state(job), "running") << job.dump();
    return state(job) == "running";
  }
};

// Pause, resume and cancel through the page or client of another host than
// the one cutting: left for that host in the store, done by it at once.
TEST(Daemon, AJobCutOnOneHostIsPausedResumedAndCancelledThroughAnother) {
  TwoHostsOneCutting lab;
  ASSERT_TRUE(lab.cutting());
  const CommandResult paused = lab.b.client(fmt::format("pause {}", lab.id));
  EXPECT_EQ(paused.status, 0) << paused.err;
  EXPECT_EQ(paused.out, fmt::format("job {0}: running on host a: asked it to pause it (`rotafab status {0}` says when "
                                    "it has)\n",
                                    lab.id));
  EXPECT_EQ(state(lab.b.waitForJob(
                lab.id, [](const json& j) { return state(j) == "paused"; }, 10)),
            "paused");
  EXPECT_EQ(lab.b.client(fmt::format("resume {}", lab.id)).status, 0);
  EXPECT_EQ(state(lab.b.waitForJob(
                lab.id, [](const json& j) { return state(j) == "running"; }, 10)),
            "running");
  // A resume of a job that is not paused is refused here, in the words a local one gets.
  const CommandResult refused = lab.b.client(fmt::format("resume {}", lab.id));
  EXPECT_EQ(refused.status, 1);
  EXPECT_NE(refused.err.find("only a paused, interrupted or failed job can be resumed"), std::string::npos)
      << refused.err;
  EXPECT_EQ(lab.b.client(fmt::format("cancel {}", lab.id)).status, 0);
  const json cancelled = lab.b.waitForJob(
      lab.id, [](const json& j) { return state(j) == "cancelled"; }, 10);
  EXPECT_EQ(state(cancelled), "cancelled") << cancelled.dump();
  EXPECT_NE(cancelled.value("message", "").find("cancelled by "), std::string::npos) << cancelled.dump();
  EXPECT_NE(cancelled.value("message", "").find("laser off"), std::string::npos) << cancelled.dump();
  EXPECT_TRUE(readFile(lab.witness).ends_with("off\n")) << readFile(lab.witness);
  EXPECT_EQ(statesOf(cancelled),
            (std::vector<std::string>{"queued", "planning", "ready", "running", "paused", "running", "cancelled"}));
}

// A host stalled past its lease (here stopped by SIGSTOP; a hung machine, a
// cut network) finds on waking that another host released its cut: it
// stops the cut at once, laser off, and the job stays interrupted.
TEST(Daemon, AHostWhoseLeaseRanOutWhileItCutStopsItsLaserAndLeavesTheJobInterrupted) {
  TwoHostsOneCutting lab;
  ASSERT_TRUE(lab.cutting());
  // Stopped while its laser burns.
  ASSERT_TRUE(eventually([&] { return readFile(lab.witness).ends_with("on\n"); }, 20)) << readFile(lab.witness);
  lab.a.signal(SIGSTOP);
  const json released = lab.b.waitForJob(
      lab.id, [](const json& j) { return state(j) == "interrupted"; }, 30);
  lab.a.signal(SIGCONT);
  EXPECT_EQ(state(released), "interrupted") << released.dump();
  EXPECT_TRUE(eventually([&] { return readFile(lab.a.log()).find(": stopping its ") != std::string::npos; }, 10))
      << readFile(lab.a.log());
  // Its laser goes off and stays off: the cut does not go on. (Seen off
  // between two strokes is not enough: off, and unchanged for a second.)
  std::string seen = readFile(lab.witness);
  const bool stoppedOff = eventually(
      [&] {
        std::this_thread::sleep_for(std::chrono::seconds(1));
        const std::string now = readFile(lab.witness);
        const bool still = now == seen && now.ends_with("off\n");
        seen = now;
        return still;
      },
      15);
  EXPECT_TRUE(stoppedOff) << seen;
  // It joins again, and nothing it did after its lease ran out counts.
  const auto laserA = [&] {
    const json devices = lab.b.clientJson("devices --daemon")["devices"];
    for (const json& device : devices) {
      if (device["name"] == "laser-a") return device;
    }
    return json::object();
  };
  EXPECT_TRUE(eventually([&] { return laserA().value("state", "") == "idle"; }, 10))
      << lab.b.clientJson("devices --daemon").dump();
  EXPECT_EQ(state(lab.b.job(lab.id)), "interrupted");
  EXPECT_EQ(statesOf(lab.b.job(lab.id)),
            (std::vector<std::string>{"queued", "planning", "ready", "running", "interrupted"}));
  EXPECT_EQ(service::openPostgresStore(lab.database.uri())->integrityCheck(), "ok");
}

TEST(Daemon, WithNoDaemonTheClientSaysSoAndHowToStartIt) {
  TempDir root;
  Daemon daemon(root.path());  // not started
  const CommandResult r = daemon.client("jobs");
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err, fmt::format("error: no rotafabd answers on {}: start it with `rotafabd` (in another terminal, or as "
                               "a service), or give --server URL\n",
                               daemon.socket().string()));
}

// A job made for a material is cut with that material's power, speed and
// passes, not the device's: plywood on the GRBL machine cuts in 4 passes,
// posterboard (the device's) in 2.
TEST(Daemon, AJobIsCutWithTheMaterialItWasMadeFor) {
  TempDir root;
  Daemon daemon(root.path(),
                "devices: [{name: laser1, machine: grbl-diode-400, material: posterboard, "
                "uri: \"sim:grbl?speed=400\"}]\n");
  daemon.start();
  const CommandResult submitted = daemon.client("submit " + quoted(kSource / "examples/cube.obj") +
                                                " --structure band --material plywood-3mm --evaluations 1 --json");
  ASSERT_EQ(submitted.status, 0) << submitted.err;
  const long long id = json::parse(submitted.out)["id"];
  const json ready =
      daemon.waitForJob(id, [](const json& job) { return job["state"] != "queued" && job["state"] != "planning"; });
  ASSERT_EQ(ready["state"], "ready") << ready.dump();
  const RawReply sheet = daemon.get(fmt::format("/api/jobs/{}/sheets/1", id));
  ASSERT_EQ(sheet.status, 200) << sheet.text;
  int cutPasses = 0;
  for (const json& stroke : sheet.body["strokes"]) {
    if (stroke["operation"] == "cut") cutPasses = std::max(cutPasses, stroke["pass"].get<int>());
  }
  EXPECT_EQ(cutPasses, 4) << "plywood-3mm's passes on grbl-diode-400";
  EXPECT_EQ(ready["summary"]["material"], "plywood-3mm");
  EXPECT_EQ(ready["summary"]["machine"], "grbl-diode-400");
  const CommandResult status = daemon.client(fmt::format("status {}", id));
  EXPECT_NE(status.out.find("  sheets of plywood-3mm (3 mm), 400 x 400 mm, cut on grbl-diode-400\n"), std::string::npos)
      << status.out;
  ASSERT_EQ(daemon.client(fmt::format("start {}", id)).status, 0);
  const json done = daemon.waitForJob(id, [](const json& job) { return job["state"] == "done"; });
  ASSERT_EQ(done["state"], "done") << done.dump();
  EXPECT_EQ(done["strokes"].get<size_t>(), sheet.body["strokes"].size()) << "the strokes cut are plywood's";
}

// A job whose machine and device disagree is refused when it is submitted,
// not when its cut fails: a mesh asked for another machine than its
// device's, and a folder made for another machine (sent, unnamed, to a
// device of its own machine where there is one).
TEST(Daemon, ASubmissionWhoseMachineAndDeviceDisagreeIsRefusedAtOnce) {
  TempDir root;
  Daemon daemon(root.path(),
                "devices: [{name: laser1, machine: grbl-diode-400, uri: \"sim:grbl?speed=400\"}, "
                "{name: k40, machine: k40-m2nano, uri: \"sim:m2nano?speed=400\"}]\n");
  daemon.start();
  const CommandResult mesh = daemon.client("submit " + quoted(kSource / "examples/cube.obj") +
                                           " --structure band --machine workshop-32x18 --device laser1");
  EXPECT_EQ(mesh.status, 1);
  EXPECT_NE(mesh.err.find("device laser1 is a grbl-diode-400, not the workshop-32x18 asked for"), std::string::npos)
      << mesh.err;
  EXPECT_EQ(daemon.clientJson("jobs --json")["jobs"].size(), 0U) << "nothing queued";
  const fs::path k40 = root.path() / "k40-cube";
  ASSERT_EQ(run(kCli + " make " + quoted(kSource / "examples/cube.obj") +
                " --structure band --machine k40-m2nano --size 4in --time 0 --out " + quoted(k40))
                .status,
            0);
  const CommandResult folder = daemon.client("submit " + quoted(k40) + " --device laser1");
  EXPECT_EQ(folder.status, 1);
  EXPECT_NE(folder.err.find("device laser1 is a grbl-diode-400, not the k40-m2nano the folder was made for: make it "
                            "again with --machine grbl-diode-400, or name a device of that machine (k40)"),
            std::string::npos)
      << folder.err;
  const json unnamed = daemon.clientJson("submit " + quoted(k40));
  EXPECT_EQ(unnamed["device"], "k40") << unnamed.dump();
}

// A job moves to another device: as it is to one of its machine, planned
// again from its mesh for another machine; a folder made for one machine
// stays on it; and a job whose device is no longer configured says so and moves.
TEST(Daemon, AJobMovesToAnotherDeviceAndOneWhoseDeviceIsGoneSaysSo) {
  TempDir root;
  const std::string three =
      "devices: [{name: laser1, machine: grbl-diode-400, uri: \"sim:grbl?speed=400\"}, "
      "{name: laser2, machine: grbl-diode-400, uri: \"sim:grbl?speed=400\"}, "
      "{name: k40, machine: k40-m2nano, uri: \"sim:m2nano?speed=400\"}]\n";
  Daemon daemon(root.path(), three);
  daemon.start();
  const long long folder = daemon.clientJson("submit " + quoted(threeSheets()) + " --device laser1")["id"];
  ASSERT_EQ(state(daemon.waitForJob(folder, [](const json& j) { return state(j) == "ready"; })), "ready");
  const CommandResult same = daemon.client(fmt::format("move {} --device laser2", folder));
  ASSERT_EQ(same.status, 0) << same.err;
  EXPECT_EQ(daemon.job(folder)["device"], "laser2");
  EXPECT_EQ(state(daemon.job(folder)), "ready");
  const CommandResult other = daemon.client(fmt::format("move {} --device k40", folder));
  EXPECT_EQ(other.status, 1);
  EXPECT_NE(other.err.find("its sheets planned for grbl-diode-400 (a folder is cut as it was made); k40 is a "
                           "k40-m2nano: a device of grbl-diode-400 can cut them"),
            std::string::npos)
      << other.err;
  // A mesh's job, planned again for the K40's bed.
  const long long mesh = daemon.clientJson("submit " + quoted(kSource / "examples/cube.obj") +
                                           " --structure band --size 4in --evaluations 1 --device laser1")["id"];
  ASSERT_EQ(state(daemon.waitForJob(mesh, [](const json& j) { return state(j) == "ready"; })), "ready");
  ASSERT_EQ(daemon.client(fmt::format("move {} --device k40", mesh)).status, 0);
  json moved = daemon.waitForJob(mesh, [](const json& j) { return state(j) == "ready" && j["device"] == "k40"; });
  ASSERT_EQ(state(moved), "ready") << moved.dump();
  EXPECT_EQ(moved["summary"]["machine"], "k40-m2nano") << moved.dump();
  // laser2 taken out of the configuration: its job says so, and moves.
  daemon.signal(SIGTERM);
  ASSERT_EQ(daemon.wait(30), 0);
  const std::string two =
      "devices: [{name: laser1, machine: grbl-diode-400, uri: \"sim:grbl?speed=400\"}, "
      "{name: k40, machine: k40-m2nano, uri: \"sim:m2nano?speed=400\"}]\n";
  std::ofstream(root.path() / "rotafabd.yaml") << two;
  daemon.start();
  EXPECT_EQ(daemon.job(folder).value("device_missing", ""), "laser2 is no longer configured (on any running host)");
  EXPECT_NE(daemon.client("jobs").out.find("laser2 is no longer configured (on any running host)"), std::string::npos)
      << daemon.client("jobs").out;
  EXPECT_NE(
      daemon.client(fmt::format("status {}", folder))
          .out.find(fmt::format(
              "laser2 is no longer configured (on any running host): move it to another device with `rotafab move {} "
              "--device NAME`",
              folder)),
      std::string::npos);
  ASSERT_EQ(daemon.client(fmt::format("move {} --device laser1", folder)).status, 0);
  EXPECT_FALSE(daemon.job(folder).contains("device_missing"));
  ASSERT_EQ(daemon.client(fmt::format("start {}", folder)).status, 0);
  EXPECT_EQ(daemon.job(folder)["device"], "laser1");
  daemon.client(fmt::format("cancel {}", folder));
}

}  // namespace
}  // namespace rotafab::test
