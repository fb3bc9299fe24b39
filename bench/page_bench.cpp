// The workshop page's assembly guide on a large structure, in headless
// Chromium (tests/support/Browser.h): the bunny's 3,674 band panels planned
// by the built daemon, the guide opened on them, and the frames drawn per
// second while the view orbits, by the page's own requestAnimationFrame
// count. The target: at least 30 frames per second.
//
//   build/rotafab_page_bench [MESH] [SECONDS]    (default examples/bunny.obj, 5)
//
// Prints one line of JSON; exit status 1 under 30 frames per second.

#include <fcntl.h>
#include <fmt/format.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <thread>

#include "support/Browser.h"

extern char** environ;

namespace {
namespace fs = std::filesystem;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

std::string quoted(const std::string& text) { return "'" + text + "'"; }

// A command's standard output; throws when it fails.
std::string output(const std::string& command) {
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) throw std::runtime_error("cannot run " + command);
  std::string text;
  char buffer[4096];
  while (size_t n = std::fread(buffer, 1, sizeof buffer, pipe)) text.append(buffer, n);
  if (::pclose(pipe) != 0) throw std::runtime_error(command + " failed: " + text);
  return text;
}

}  // namespace

int main(int argc, char** argv) {
  const fs::path mesh = argc > 1 ? fs::path(argv[1]) : fs::path(ROTAFAB_SOURCE_DIR) / "examples/bunny.obj";
  const int seconds = argc > 2 ? std::stoi(argv[2]) : 5;
  char pattern[] = "/tmp/rotafab-page-bench-XXXXXX";
  const fs::path root = ::mkdtemp(pattern);
  fs::create_directories(root / "state");
  fs::create_directories(root / "run");
  const std::string env = fmt::format("env XDG_STATE_HOME={} XDG_RUNTIME_DIR={} ", quoted((root / "state").string()),
                                      quoted((root / "run").string()));
  // The daemon with its defaults: the page on loopback TCP.
  const std::string state = "XDG_STATE_HOME=" + (root / "state").string();
  const std::string run = "XDG_RUNTIME_DIR=" + (root / "run").string();
  std::vector<char*> envp;
  for (char** e = environ; *e; ++e) envp.push_back(*e);
  envp.push_back(const_cast<char*>(state.c_str()));
  envp.push_back(const_cast<char*>(run.c_str()));
  envp.push_back(nullptr);
  const std::string program = ROTAFAB_DAEMON, log = (root / "daemon.log").string();
  char* args[] = {const_cast<char*>(program.c_str()), nullptr};
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  pid_t daemon = 0;
  posix_spawn(&daemon, program.c_str(), &actions, nullptr, args, envp.data());
  posix_spawn_file_actions_destroy(&actions);
  int status = 0;
  try {
    const std::string cli = env + ROTAFAB_CLI;
    for (int tenth = 0; tenth < 200 && !fs::exists(root / "run/rotafab/rotafabd.sock"); ++tenth) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    // In rows: the sheets do not matter here, the structure does.
    const json job =
        json::parse(output(cli + " submit " + quoted(mesh.string()) + " --structure band --layout rows --json 2>&1"));
    const long long id = job["id"];
    json planned;
    for (int second = 0; second < 600; ++second) {
      planned = json::parse(output(fmt::format("{} status {} --json", cli, id)));
      if (planned["state"] != "queued" && planned["state"] != "planning") break;
      std::this_thread::sleep_for(std::chrono::seconds(1));
    }
    if (planned["state"] != "ready") throw std::runtime_error("the job was not planned: " + planned.dump());
    const std::string link = output(cli + " dashboard --url");
    const int width = std::getenv("PAGE_W") ? std::atoi(std::getenv("PAGE_W")) : 1280;
    rotafab::testing::Browser browser(width, width * 900 / 1280);
    browser.navigate(link.substr(0, link.find('\n')));
    if (!browser.waitFor(fmt::format("document.querySelector('tr[data-job=\"{}\"] button[data-action=\"guide\"]')", id),
                         std::chrono::seconds(30))) {
      throw std::runtime_error("the queue did not show the job");
    }
    const auto opening = Clock::now();
    browser.evaluate(
        fmt::format("document.querySelector('tr[data-job=\"{}\"] button[data-action=\"guide\"]').click()", id));
    if (!browser.waitFor(fmt::format("window.rotafabGuide && window.rotafabGuide.job === {}", id),
                         std::chrono::seconds(120))) {
      throw std::runtime_error("the guide did not open");
    }
    const double opened = std::chrono::duration<double>(Clock::now() - opening).count();
    std::this_thread::sleep_for(std::chrono::seconds(1));
    const char* shots = std::getenv("ROTAFAB_PAGE_SHOTS");  // a folder for the guide at rest and in motion
    if (shots) browser.screenshot(fs::path(shots) / "guide-at-rest.png");
    // Orbiting close to the first panel (where the guide turns to), then the whole structure in view.
    const double fps = browser.evaluate(fmt::format("window.rotafabGuide.fps({})", seconds * 1000)).get<double>();
    browser.evaluate("window.rotafabGuide.whole()");
    std::this_thread::sleep_for(std::chrono::seconds(1));
    const double wholeFps = browser.evaluate(fmt::format("window.rotafabGuide.fps({})", seconds * 1000)).get<double>();
    if (shots) {
      browser.evaluate("window.rotafabGuide.fps(300).then(() => 0)");
      browser.evaluate("(() => { window.rotafabGuide.fps(2000); return new Promise(r => setTimeout(r, 500)); })()");
      browser.screenshot(fs::path(shots) / "guide-in-motion.png");
    }
    // Stepping: the time the page takes for 100 steps forward.
    const double stepping = browser
                                .evaluate(
                                    "(() => { const t = performance.now(); for (let i = 0; i < 100; i++) "
                                    "document.getElementById('guide-next').click(); return performance.now() - "
                                    "t; })()")
                                .get<double>();
    const json result{{"mesh", mesh.filename().string()},
                      {"panels", browser.evaluate("window.rotafabGuide.panels")},
                      {"triangles", browser.evaluate("window.rotafabGuide.triangles")},
                      {"guide_opened_s", std::round(opened * 100) / 100},
                      {"fps_at_a_panel", std::round(fps * 10) / 10},
                      {"fps_whole", std::round(wholeFps * 10) / 10},
                      {"step_ms", std::round(stepping) / 100},
                      {"errors", browser.errors().size()}};
    std::printf("%s\n", result.dump().c_str());
    status = std::min(fps, wholeFps) >= 30 && browser.errors().empty() ? 0 : 1;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "page bench: %s\n", error.what());
    status = 2;
  }
  ::kill(daemon, SIGTERM);
  ::waitpid(daemon, nullptr, 0);
  std::error_code ignored;
  fs::remove_all(root, ignored);
  return status;
}
