// The workshop page in a real browser: Debian's Chromium, headless, driven
// over its DevTools protocol (support/Browser.h), against the built daemon
// and its simulated GRBL. What a newcomer does: sign in with the link of
// `rotafab dashboard`, drop a mesh, watch it plan, start it, watch the cut
// reach 100%, look at the sheet, and step through the assembly in 3D. Each
// page is kept as a screenshot in the build tree (test-artefacts/page/), and
// the page must have reported no error at all.

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <pwd.h>
#include <regex>

#include <algorithm>

#include "daemon/DaemonSupport.h"
#include "support/Browser.h"
#include "support/TestDatabase.h"

namespace rotafab::test {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;
using namespace std::chrono_literals;

fs::path artefacts() {
  const fs::path folder = fs::path(ROTAFAB_BUILD_DIR) / "test-artefacts/page";
  fs::create_directories(folder);
  return folder;
}

std::string loginLink(const Daemon& daemon) {
  const CommandResult link = daemon.client("dashboard --url");
  EXPECT_EQ(link.status, 0) << link.err;
  return link.out.substr(0, link.out.find('\n'));
}

// A page's JavaScript for a string: the text quoted as JSON.
std::string js(const std::string& text) { return json(text).dump(); }

void click(testing::Browser& browser, const std::string& selector) {
  const json clicked = browser.evaluate(
      fmt::format("(() => {{ const b = document.querySelector({}); if (!b) return false; b.click(); return true; }})()",
                  js(selector)));
  ASSERT_EQ(clicked, true) << "nothing to click at " << selector;
}

std::string rowState(testing::Browser& browser, long long job) {
  const json state = browser.evaluate(
      fmt::format("(document.querySelector('tr[data-job=\"{}\"]') || {{dataset: {{}}}}).dataset.state || ''", job));
  return state.is_string() ? state.get<std::string>() : "";
}

// Errors but those the browser logs for a refusal the test asked for.
void expectNoErrorsBut(const testing::Browser& browser, const std::string& expected) {
  for (const std::string& error : browser.errors()) {
    EXPECT_NE(error.find(expected), std::string::npos) << error;
  }
}

void expectNoErrors(const testing::Browser& browser) {
  const auto errors = browser.errors();
  EXPECT_TRUE(errors.empty()) << fmt::format("{} error(s) in the page, the first: {}", errors.size(),
                                             errors.empty() ? "" : errors.front());
}

TEST(Browser, ACubeDroppedOnThePageIsPlannedCutAndAssembledStepByStep) {
  TempDir root;
  // A simulated GRBL 100 times faster than the machine: the cube's sheet in about 2 s.
  Daemon daemon(root.path(), "devices: [{name: laser1, machine: grbl-diode-400, uri: \"sim:grbl?speed=100\"}]\n");
  daemon.start();
  testing::Browser browser;
  browser.navigate(loginLink(daemon));
  ASSERT_TRUE(
      browser.waitFor("document.querySelector('#connection.live') && "
                      "document.querySelector('.device[data-device=\"laser1\"][data-state=\"idle\"]')",
                      20s))
      << browser.evaluate("document.body.innerText");

  // Drop the cube (the file input the drop box stands for), band, submit.
  browser.setFiles("#mesh-file", {kSource / "examples/cube.obj"});
  browser.evaluate("document.getElementById('opt-structure').value = 'band'");
  // In inches, although the machine's bed is in millimetres (its default).
  browser.evaluate("document.getElementById('opt-units').value = 'in'");
  click(browser, "#submit-button");
  ASSERT_TRUE(browser.waitFor("document.querySelector('tr[data-job=\"1\"]')", 10s));
  ASSERT_TRUE(browser.waitFor("document.querySelector('tr[data-job=\"1\"][data-state=\"ready\"]')", 60s))
      << rowState(browser, 1) << ": " << daemon.job(1).dump();
  // The page's session is the user's who asked for the link.
  EXPECT_EQ(daemon.job(1)["owner"], ::getpwuid(::getuid())->pw_name);
  // The plan's warning, folded under the row's state.
  EXPECT_EQ(browser.evaluate("document.querySelector('tr[data-job=\"1\"] .warnings summary').textContent"),
            "1 warning from planning");
  browser.screenshot(artefacts() / "queue.png");

  // The sheet on the screen while it is cut: every percentage the
  // machine's card shows, and every stroke the sheet highlights.
  click(browser, "tr[data-job=\"1\"] button[data-action=\"sheets\"]");
  ASSERT_TRUE(browser.waitFor("document.querySelectorAll('#sheet-view polyline').length > 0", 20s));
  browser.evaluate(R"(window.percents = []; window.highlighted = [];
    new MutationObserver(() => {
      for (const bar of document.querySelectorAll('.device progress')) window.percents.push(Number(bar.dataset.percent));
    }).observe(document.getElementById('devices'), {childList: true, subtree: true});
    new MutationObserver(() => {
      const current = document.querySelector('#sheet-view polyline[data-current]');
      if (current) window.highlighted.push(Number(current.dataset.stroke));
    }).observe(document.getElementById('sheet-view'), {attributes: true, subtree: true});)");
  // Framed first, beside Start: the head traces the sheet's box, laser off, and the job stays ready.
  click(browser, "tr[data-job=\"1\"] button[data-action=\"frame\"]");
  ASSERT_TRUE(eventually(
      [&] {
        const json events = daemon.job(1)["events"];
        return events.is_array() && !events.empty() &&
               events.back().value("text", "") == "sheet 1 framed on laser1 (laser off)";
      },
      20))
      << daemon.job(1).dump();
  ASSERT_TRUE(
      browser.waitFor("document.querySelector('tr[data-job=\"1\"] button[data-action=\"start\"]') && "
                      "document.querySelector('.device[data-device=\"laser1\"][data-state=\"idle\"]')",
                      10s));
  click(browser, "tr[data-job=\"1\"] button[data-action=\"start\"]");
  ASSERT_TRUE(browser.waitFor("document.querySelector('tr[data-job=\"1\"][data-state=\"done\"]')", 60s))
      << rowState(browser, 1) << ": " << daemon.job(1).dump();
  const json percents = browser.evaluate("window.percents");
  ASSERT_TRUE(percents.is_array() && !percents.empty()) << "no progress was shown during the cut";
  EXPECT_EQ(percents.back(), 100) << percents.dump();
  EXPECT_LT(percents.front().get<int>(), 100) << percents.dump();
  EXPECT_EQ(browser.evaluate("document.querySelector('tr[data-job=\"1\"] .sheets').textContent"), "1/1");
  const json job = daemon.job(1);
  // The strokes highlighted in the order they were cut, up to the last.
  const json highlighted = browser.evaluate("window.highlighted");
  ASSERT_TRUE(highlighted.is_array() && highlighted.size() >= 2) << highlighted.dump();
  EXPECT_TRUE(std::is_sorted(highlighted.begin(), highlighted.end())) << highlighted.dump();
  EXPECT_GT(highlighted.back().get<int>(), 0);
  EXPECT_LT(highlighted.back().get<int>(), job["strokes"].get<int>());
  EXPECT_EQ(browser.evaluate("document.querySelector('#sheet-view polyline[data-current]')"), nullptr);

  // Its lengths in the unit asked, the page's and the daemon's alike.
  EXPECT_EQ(job["summary"].value("units", ""), "in") << job.dump();
  EXPECT_NE(browser.evaluate("document.getElementById('sheet-info').textContent").get<std::string>().find(" in burnt,"),
            std::string::npos);
  EXPECT_NE(job["summary"].value("stock", "").find("15.748 x 15.748 in"), std::string::npos) << job.dump();
  // The sheet as it was burnt: every stroke drawn, all of them cut.
  EXPECT_EQ(browser.evaluate("document.querySelectorAll('#sheet-view polyline').length"), job["strokes"]);
  EXPECT_EQ(browser.evaluate("document.querySelectorAll('#sheet-view polyline.done').length"), job["strokes"]);
  EXPECT_EQ(browser.evaluate("getComputedStyle(document.querySelector('#sheet-view polyline')).strokeWidth"), "1.5px");
  // Every operation's strokes stand out from the sheet (WCAG 2's contrast
  // for graphics, 3:1, computed here from the colours the browser draws):
  // the machine's yellow etch would not (1.1:1).
  const json contrasts = browser.evaluate(R"((() => {
    const rgb = (text) => text.match(/\d+/g).slice(0, 3).map(Number);
    const luminance = ([r, g, b]) => [r, g, b].map((c) => c / 255)
      .map((c) => (c <= 0.03928 ? c / 12.92 : ((c + 0.055) / 1.055) ** 2.4))
      .reduce((sum, c, i) => sum + c * [0.2126, 0.7152, 0.0722][i], 0);
    const sheet = luminance(rgb(getComputedStyle(document.querySelector('#sheet-view rect')).fill));
    const byOperation = {};
    for (const line of document.querySelectorAll('#sheet-view polyline')) {
      const stroke = luminance(rgb(getComputedStyle(line).stroke));
      const ratio = (Math.max(stroke, sheet) + 0.05) / (Math.min(stroke, sheet) + 0.05);
      const operation = line.dataset.operation;
      byOperation[operation] = Math.min(byOperation[operation] ?? Infinity, ratio);
    }
    return byOperation;
  })())");
  ASSERT_TRUE(contrasts.contains("etch")) << contrasts.dump();
  for (const auto& [operation, ratio] : contrasts.items()) EXPECT_GE(ratio.get<double>(), 3.0) << operation;
  browser.screenshot(artefacts() / "sheet.png");

  // The assembly guide, stepped to panel 3.
  click(browser, "tr[data-job=\"1\"] button[data-action=\"guide\"]");
  ASSERT_TRUE(browser.waitFor("window.rotafabGuide && window.rotafabGuide.job === 1", 20s));
  const json manifest = daemon.get("/api/jobs/1/manifest").body;
  ASSERT_EQ(browser.evaluate("window.rotafabGuide.panels"), manifest["panels"].size());
  for (int press = 0;
       press < 10 && browser.evaluate("document.getElementById('guide-panel-number').textContent") != "3"; ++press) {
    click(browser, "#guide-next");
  }
  ASSERT_EQ(browser.evaluate("document.getElementById('guide-panel-number').textContent"), "3");
  // What is drawn as the next panel is panel 3 alone, at the step the manifest gives it.
  EXPECT_EQ(browser.evaluate("window.rotafabGuide.highlighted()"), json::array({3}));
  const int step = browser.evaluate("window.rotafabGuide.step()").get<int>();
  json three;
  for (const json& panel : manifest["panels"]) {
    if (panel["id"] == 3) three = panel;
  }
  ASSERT_TRUE(three.is_object());
  EXPECT_EQ(step, 3) << "the guide steps in assembly order (a panel's id), not in cutting order";
  // The guide's steps are manifest.txt's: each panel in assembly order, on its sheet.
  const auto expectTheStepsOfTheText = [&](int job) {
    const CommandResult text = daemon.client(fmt::format("manifest {}", job));
    ASSERT_EQ(text.status, 0) << text.err;
    json stepsOfText = json::array();
    const std::regex stepLine(R"(step +(\d+): panel (\d+) \(sheet (\d+)\))");
    for (auto line = std::sregex_iterator(text.out.begin(), text.out.end(), stepLine); line != std::sregex_iterator();
         ++line) {
      stepsOfText.push_back({std::stoi((*line)[2].str()), std::stoi((*line)[3].str())});
    }
    EXPECT_EQ(stepsOfText.size(), daemon.get(fmt::format("/api/jobs/{}/manifest", job)).body["panels"].size())
        << text.out;
    EXPECT_EQ(browser.evaluate("[...document.querySelectorAll('#guide-print-steps li')].map((li) => "
                               "[Number(li.dataset.panel), Number(li.dataset.sheet)])"),
              stepsOfText);
  };
  expectTheStepsOfTheText(1);
  // Its sheet and neighbours as the manifest says.
  EXPECT_EQ(browser.evaluate("document.getElementById('guide-panel-sheet').textContent"),
            std::to_string(three["sheet"].get<int>()));
  const std::string neighbours =
      browser.evaluate("document.getElementById('guide-panel-neighbours').textContent").get<std::string>();
  for (const json& id : three["neighbors"]) {
    EXPECT_NE(neighbours.find(std::to_string(id.get<int>())), std::string::npos) << neighbours;
  }
  // A panel found by its number.
  browser.evaluate("document.getElementById('guide-find-number').value = '5'");
  click(browser, "#guide-find button[type=submit]");
  ASSERT_TRUE(browser.waitFor("document.getElementById('guide-panel-number').textContent === '5'", 5s));
  EXPECT_EQ(browser.evaluate("window.rotafabGuide.highlighted()"), json::array({5}));
  browser.screenshot(artefacts() / "guide.png");
  // A job cut in the free order, whose cutting order is not its assembly
  // order (larger panels first): the guide still steps as manifest.txt does.
  const CommandResult free = daemon.client("submit " + quoted(kSource / "examples/soccer-ball.obj") +
                                           " --structure band --order free --time 2");
  ASSERT_EQ(free.status, 0) << free.err;
  ASSERT_EQ(daemon.waitForJob(2, [](const json& job) { return job["state"] == "ready"; })["state"], "ready");
  const json freeManifest = daemon.get("/api/jobs/2/manifest").body;
  ASSERT_TRUE(std::any_of(freeManifest["panels"].begin(), freeManifest["panels"].end(), [](const json& panel) {
    return panel["order"] != panel["id"];
  })) << "the free order cut the panels in their assembly order: this job tests nothing";
  click(browser, "tr[data-job=\"2\"] button[data-action=\"guide\"]");
  ASSERT_TRUE(browser.waitFor("window.rotafabGuide && window.rotafabGuide.job === 2", 20s));
  EXPECT_EQ(browser.evaluate("window.rotafabGuide.panel()"), 1) << "step 1 is panel 1, the base";
  expectTheStepsOfTheText(2);
  expectNoErrors(browser);
}

TEST(Browser, ARefusedActionShowsTheDaemonsOwnWords) {
  TempDir root;
  // A simulated cutter in real time, busy with job 1: starting job 2 is
  // refused (the page offers Start, as the device can cut; it cannot yet).
  Daemon daemon(root.path(), "devices: [{name: laser1, machine: grbl-diode-400, uri: \"sim:grbl?speed=1\"}]\n");
  daemon.start();
  for (int job = 1; job <= 2; ++job) {
    const CommandResult submitted =
        daemon.client("submit " + quoted(kSource / "examples/cube.obj") + " --structure band --evaluations 1");
    ASSERT_EQ(submitted.status, 0) << submitted.err;
    ASSERT_EQ(daemon.waitForJob(job, [](const json& j) { return j["state"] == "ready"; })["state"], "ready");
  }
  ASSERT_EQ(daemon.client("start 1").status, 0);
  testing::Browser browser;
  browser.navigate(loginLink(daemon));
  ASSERT_TRUE(
      browser.waitFor("document.querySelector('tr[data-job=\"2\"][data-state=\"ready\"] "
                      "button[data-action=\"start\"]')",
                      20s))
      << browser.evaluate("document.getElementById('jobs-body').innerText");
  // What the API says to the same request.
  const RawReply refused = daemon.post("/api/jobs/2/start", "{}");
  ASSERT_EQ(refused.status, 409) << refused.text;
  const std::string words = refused.body["error"];
  EXPECT_NE(words.find("busy with job 1"), std::string::npos) << words;
  click(browser, "tr[data-job=\"2\"] button[data-action=\"start\"]");
  ASSERT_TRUE(browser.waitFor("!document.getElementById('error').hidden", 10s));
  EXPECT_EQ(browser.evaluate("document.getElementById('error-text').textContent"), words);
  EXPECT_EQ(daemon.job(2)["state"], "ready");
  ASSERT_EQ(daemon.client("cancel 1").status, 0);
  browser.screenshot(artefacts() / "refused.png");
  // The browser logs the 409 of the request; nothing else went wrong.
  expectNoErrorsBut(browser, "status of 409");
}

// Two hosts on one store: the page of either shows every host's devices
// with their host, each job's host while it cuts, and a host that is gone.
TEST(Browser, OnASharedStoreThePageShowsEachDevicesHostAndAHostThatIsGone) {
  TestDatabase database;
  TempDir shared, rootA, rootB;
  const auto config = [&](const std::string& host, const std::string& speed) {
    return fmt::format(
        "store: {}\nhost: {}\nspool: {}\nlease: 3\ndevices: [{{name: laser-{}, machine: grbl-diode-400, uri: "
        "\"sim:grbl?speed={}\", auto_start: true}}]\n",
        database.uri(), host, shared.path().string(), host, speed);
  };
  Daemon a(rootA.path(), config("a", "2"));
  Daemon b(rootB.path(), config("b", "100"));
  a.start();
  b.start();
  const CommandResult planned =
      run(kCli + " make " + quoted(kSource / "examples/cube.obj") +
          " --structure band --machine grbl-diode-400 --evaluations 1 --out " + quoted(shared.path() / "cube"));
  ASSERT_EQ(planned.status, 0) << planned.err;
  const long long id = b.clientJson("submit " + quoted(shared.path() / "cube") + " --device laser-a --json")["id"];
  testing::Browser browser;
  browser.navigate(loginLink(b));
  // The job cut by host a, as host b's page shows it.
  ASSERT_TRUE(browser.waitFor(
      fmt::format("(document.querySelector('tr[data-job=\"{}\"]') || {{}}).innerText?.includes('laser-a@a')", id), 20s))
      << browser.evaluate("document.getElementById('jobs').innerText");
  ASSERT_TRUE(browser.waitFor(
      "(document.querySelector('.device[data-device=\"laser-a\"] .device-host') || {}).textContent === 'on host a'",
      10s));
  a.kill9();
  ASSERT_TRUE(browser.waitFor("document.querySelector('.host.gone[data-host=\"a\"]')", 20s))
      << browser.evaluate("document.getElementById('hosts').innerText");
  ASSERT_TRUE(browser.waitFor("document.querySelector('.device[data-device=\"laser-a\"][data-state=\"gone\"]')", 10s));
  ASSERT_TRUE(browser.waitFor(
      fmt::format("document.querySelector('tr[data-job=\"{}\"][data-state=\"interrupted\"]')", id), 10s));
  EXPECT_NE(browser.evaluate("document.getElementById('hosts').innerText").get<std::string>().find("b: up"),
            std::string::npos);
  browser.screenshot(artefacts() / "shared-store.png");
  expectNoErrors(browser);
}

// The queue's order as the API gives it.
std::vector<int> queueOrder(const Daemon& daemon) {
  std::vector<int> order;
  const json queue = daemon.clientJson("jobs");
  for (const json& job : queue["jobs"]) order.push_back(job["id"].get<int>());
  return order;
}

TEST(Browser, TheQueueIsReorderedByDraggingItsRowsUpAndDown) {
  TempDir root;
  // A cutter that is not plugged in: nothing starts while the rows are moved;
  // beside it a fab lab's CO2 laser on its (simulated) Ruida controller.
  Daemon daemon(root.path(),
                "devices: [{name: laser1, machine: grbl-diode-400, uri: \"grbl:///dev/rotafab-no-such-port\"}, "
                "{name: co2, machine: ruida-co2-60w, uri: \"sim:ruida\"}]\n");
  daemon.start();
  for (int n = 0; n < 3; ++n) {
    ASSERT_EQ(daemon
                  .client("submit " + quoted(kSource / "examples/cube.obj") +
                          " --structure band --evaluations 1 --device laser1")
                  .status,
              0);
  }
  testing::Browser browser;
  browser.navigate(loginLink(daemon));
  ASSERT_TRUE(browser.waitFor("document.querySelectorAll('#jobs-body tr').length === 3", 20s));
  // The Ruida is shown as any cutter: idle, with what its controller said it is.
  EXPECT_TRUE(
      browser.waitFor("(d => d && d.textContent.includes('ruida-co2-60w') && "
                      "d.textContent.includes('Ruida controller (card 0x65106510, bed 700 x 500 mm)'))("
                      "document.querySelector('.device[data-device=\"co2\"][data-state=\"idle\"]'))",
                      20s))
      << browser.evaluate("document.querySelector('#devices') && document.querySelector('#devices').innerText").dump();
  // Each planned job's row says what it is cut with, and on what.
  EXPECT_TRUE(
      browser.waitFor("[...document.querySelectorAll('#jobs-body .cut-with')].map(e => e.textContent).join("
                      "'|') === Array(3).fill('posterboard on grbl-diode-400').join('|')",
                      20s))
      << browser.evaluate("document.querySelector('#jobs-body').innerText").dump();
  // Its device is not plugged in: no Start offered, but why.
  EXPECT_TRUE(browser.waitFor("document.querySelectorAll('#jobs-body .unable').length === 3", 20s))
      << browser.evaluate("document.querySelector('#jobs-body').innerText").dump();
  EXPECT_EQ(browser.evaluate("document.querySelectorAll('#jobs-body button[data-action=start]').length"), 0);
  EXPECT_TRUE(browser.evaluate("document.querySelector('#jobs-body .unable').textContent")
                  .get<std::string>()
                  .starts_with("laser1 is offline"));
  // A drag as the browser delivers one: dragstart on a row, drop on another.
  const auto drag = [&](int job, int onto) {
    browser.evaluate(fmt::format(R"((() => {{
      const data = new DataTransfer();
      document.querySelector('tr[data-job="{}"]').dispatchEvent(new DragEvent('dragstart', {{dataTransfer: data, bubbles: true}}));
      document.querySelector('tr[data-job="{}"]').dispatchEvent(new DragEvent('drop', {{dataTransfer: data, bubbles: true, cancelable: true}}));
    }})())",
                                 job, onto));
  };
  drag(1, 3);  // down, below the last
  ASSERT_TRUE(browser.waitFor(
      "[...document.querySelectorAll('#jobs-body tr')].map(r => r.dataset.job).join() === '2,3,1'", 10s));
  EXPECT_EQ(queueOrder(daemon), (std::vector<int>{2, 3, 1}));
  drag(2, 3);  // down, onto the next
  ASSERT_TRUE(browser.waitFor(
      "[...document.querySelectorAll('#jobs-body tr')].map(r => r.dataset.job).join() === '3,2,1'", 10s));
  drag(1, 3);  // up, to the top
  ASSERT_TRUE(browser.waitFor(
      "[...document.querySelectorAll('#jobs-body tr')].map(r => r.dataset.job).join() === '1,3,2'", 10s));
  EXPECT_EQ(queueOrder(daemon), (std::vector<int>{1, 3, 2}));
  expectNoErrors(browser);
}

TEST(Browser, WithoutASessionThePageSaysHowToGetOneAndSoItDoesWhenTheDaemonStartsAgain) {
  TempDir root;
  const int port = freePort();
  Daemon daemon(root.path(), fmt::format("listen: [unix:{}, tcp://127.0.0.1:{}]\n",
                                         (root.path() / "run/rotafab/rotafabd.sock").string(), port));
  daemon.start();
  testing::Browser browser;
  // No session yet: the page says what to do, and shows no queue.
  browser.navigate(fmt::format("http://127.0.0.1:{}/", port));
  ASSERT_TRUE(browser.waitFor("!document.getElementById('signed-out').hidden", 10s));
  EXPECT_NE(
      browser.evaluate("document.getElementById('signed-out').innerText").get<std::string>().find("rotafab dashboard"),
      std::string::npos);
  EXPECT_EQ(browser.evaluate("document.querySelector('main').offsetParent"), nullptr);
  // Signed in by a link; the secret does not stay in the address, and a reload keeps the session.
  const std::string link = loginLink(daemon);
  browser.navigate(link);
  ASSERT_TRUE(browser.waitFor("document.querySelector('#connection.live')", 20s));
  EXPECT_EQ(browser.evaluate("location.href"), fmt::format("http://127.0.0.1:{}/", port));
  browser.navigate(fmt::format("http://127.0.0.1:{}/", port));
  ASSERT_TRUE(browser.waitFor("document.querySelector('#connection.live')", 20s));
  EXPECT_EQ(browser.evaluate("document.getElementById('signed-out').hidden"), true);
  // The same link again, in another tab of the same browser, still signed in.
  browser.navigate(link);
  ASSERT_TRUE(browser.waitFor("document.querySelector('#connection.live')", 20s));
  // The daemon started again: sessions end, and the open page says so by itself.
  daemon.signal(SIGTERM);
  ASSERT_EQ(daemon.wait(), 0);
  daemon.start();
  ASSERT_TRUE(browser.waitFor("!document.getElementById('signed-out').hidden", 20s))
      << browser.evaluate("document.getElementById('connection').textContent");
  EXPECT_NE(
      browser.evaluate("document.getElementById('signed-out-why').textContent").get<std::string>().find("starts again"),
      std::string::npos);
  browser.screenshot(artefacts() / "signed-out.png");
  expectNoErrorsBut(browser, "status of 401");
}

TEST(Browser, OnATabletThePageFitsTheScreen) {
  TempDir root;
  Daemon daemon(root.path());
  daemon.start();
  testing::Browser browser;
  browser.setViewport(820, 1180, true, 2);
  browser.navigate(loginLink(daemon));
  ASSERT_TRUE(browser.waitFor("document.querySelector('#connection.live') && document.querySelector('.device')", 20s));
  EXPECT_EQ(browser.evaluate("document.documentElement.scrollWidth <= window.innerWidth"), true)
      << browser.evaluate("[document.documentElement.scrollWidth, window.innerWidth]").dump();
  // The buttons are large enough to press with a finger.
  EXPECT_EQ(browser.evaluate("[...document.querySelectorAll('button:not([hidden])')].filter(b => b.offsetParent)"
                             ".every(b => b.getBoundingClientRect().height >= 30)"),
            true);
  browser.screenshot(artefacts() / "tablet.png");
  expectNoErrors(browser);
}

}  // namespace
}  // namespace rotafab::test
