#pragma once
// A headless Chromium for browser tests of the pages the daemon serves,
// driven over the Chrome DevTools Protocol (CDP) on one page target.
//
// Single-threaded: every call reads the websocket until its own reply comes,
// keeping the events that arrive meanwhile, and every wait has a deadline, so
// a test fails with a message instead of hanging. Use one Browser from one
// thread, and construct it on a thread that outlives it (Chromium is told to
// die with the thread that started it, so that a crashed test leaves none
// behind). A page's alert/confirm/prompt is accepted at once: a dialog would
// otherwise stop the page and time out every later call.

#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace rotafab::testing {

class Browser {
 public:
  // Starts chromium (or $ROTAFAB_CHROMIUM) headless with a fresh profile in a
  // temporary folder and connects to its page. Throws std::runtime_error if
  // chromium is missing or does not start within about 20 s, quoting the end
  // of its log.
  explicit Browser(int width = 1280, int height = 900);
  // Closes the connection, stops chromium (SIGTERM, SIGKILL after 5 s) and
  // removes the temporary folder.
  ~Browser();
  Browser(const Browser&) = delete;
  Browser& operator=(const Browser&) = delete;

  // One CDP command; returns its "result". Throws on an error reply or the
  // timeout, naming the method.
  nlohmann::json call(const std::string& method, nlohmann::json params = nlohmann::json::object(),
                      std::chrono::milliseconds timeout = std::chrono::seconds(30));
  // Loads the URL and waits up to 30 s for its load event. Throws if the page
  // cannot be loaded (e.g. net::ERR_CONNECTION_REFUSED).
  void navigate(const std::string& url);
  // The expression's value (a promise's, once settled), as JSON; null for
  // undefined. Throws with the exception's text if the script throws, or at
  // the timeout (a longer one for a promise that measures for a while).
  nlohmann::json evaluate(const std::string& expression, std::chrono::milliseconds timeout = std::chrono::seconds(30));
  // Evaluates `condition` every 100 ms until it is truthy: true then, false at
  // the timeout. A condition that throws counts as false (the page may not
  // have defined what it looks at yet).
  bool waitFor(const std::string& condition, std::chrono::milliseconds timeout = std::chrono::seconds(10));
  // The viewport as a PNG file.
  void screenshot(const std::filesystem::path& png);
  // Chooses files on the <input type=file> the selector finds, as a user
  // would (the input's change event fires). Throws if nothing matches.
  void setFiles(const std::string& cssSelector, const std::vector<std::filesystem::path>& files);
  // Emulates a screen of this size (CSS pixels) and pixel ratio. A mobile one
  // (a tablet) has touch, and lays the page out as its <meta name=viewport>
  // says: without one, 980 px wide, as a real tablet would.
  void setViewport(int width, int height, bool mobile = false, double scale = 1);
  // Every error the page reported since the start, one line each: uncaught
  // exceptions, console.error (and failed console.assert), and the browser's
  // own error log (e.g. "Failed to load resource: ... (url)"), except for the
  // /favicon.ico that chromium asks every server for of its own accord.
  [[nodiscard]] std::vector<std::string> errors() const;
  // Where chromium's output goes, for a failing test to show.
  [[nodiscard]] std::filesystem::path logFile() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rotafab::testing
