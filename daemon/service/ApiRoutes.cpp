#include "daemon/service/ApiRoutes.h"

#include <algorithm>
#include <array>

namespace rotafab::service {

using boost::beast::http::verb;

const std::vector<Endpoint>& endpoints() {
  static const std::vector<Endpoint> table{
      // Served to anyone who reaches the listener: the page's own files,
      // which are the same for everyone and hold nothing of the queue, and
      // the login link's landing, whose one-time code is its credential.
      {Route::PageIndex, verb::get, true, BodyKind::None},
      {Route::PageFile, verb::get, true, BodyKind::None},
      {Route::PageLibrary, verb::get, true, BodyKind::None},
      {Route::Login, verb::get, true, BodyKind::None},
      {Route::Favicon, verb::get, true, BodyKind::None},
      // Everything else only to a caller the gate knows.
      {Route::About, verb::get, false, BodyKind::None},
      {Route::Sessions, verb::post, false, BodyKind::Json},
      {Route::Devices, verb::get, false, BodyKind::None},
      {Route::Events, verb::get, false, BodyKind::None},
      {Route::Jobs, verb::get, false, BodyKind::None},
      {Route::Jobs, verb::post, false, BodyKind::JsonOrForm},
      {Route::Job, verb::get, false, BodyKind::None},
      {Route::JobManifest, verb::get, false, BodyKind::None},
      {Route::JobFile, verb::get, false, BodyKind::None},
      {Route::JobSheet, verb::get, false, BodyKind::None},
      {Route::JobAction, verb::post, false, BodyKind::Json},
  };
  return table;
}

const Endpoint* endpointFor(Route route, verb method) {
  for (const Endpoint& endpoint : endpoints()) {
    if (endpoint.route == route && endpoint.method == method) return &endpoint;
  }
  return nullptr;
}

std::string methodsOf(Route route) {
  std::string names;
  for (const Endpoint& endpoint : endpoints()) {
    if (endpoint.route != route) continue;
    names += (names.empty() ? "" : " and ") + std::string(boost::beast::http::to_string(endpoint.method));
  }
  return names;
}

std::optional<MatchedRoute> matchRoute(const std::vector<std::string>& parts) {
  const size_t n = parts.size();
  const auto is = [&](size_t i, const char* word) { return i < n && parts[i] == word; };
  if (n == 0) return MatchedRoute{Route::PageIndex, "", ""};
  if (n == 1 && is(0, "login")) return MatchedRoute{Route::Login, "", ""};
  if (n == 1 && is(0, "favicon.ico")) return MatchedRoute{Route::Favicon, "", ""};
  if (n == 2 && is(0, "app")) return MatchedRoute{Route::PageFile, "", parts[1]};
  if (n > 2 && is(0, "lib") && is(1, "three")) {
    std::string rest;
    for (size_t i = 2; i < n; ++i) rest += (i > 2 ? "/" : "") + parts[i];
    return MatchedRoute{Route::PageLibrary, "", rest};
  }
  if (!is(0, "api")) return std::nullopt;
  if (n == 1) return MatchedRoute{Route::About, "", ""};
  if (n == 2 && is(1, "sessions")) return MatchedRoute{Route::Sessions, "", ""};
  if (n == 2 && is(1, "devices")) return MatchedRoute{Route::Devices, "", ""};
  if (n == 2 && is(1, "events")) return MatchedRoute{Route::Events, "", ""};
  if (!is(1, "jobs")) return std::nullopt;
  if (n == 2) return MatchedRoute{Route::Jobs, "", ""};
  const std::string& job = parts[2];
  if (n == 3) return MatchedRoute{Route::Job, job, ""};
  if (n == 4 && is(3, "manifest")) return MatchedRoute{Route::JobManifest, job, ""};
  static const std::array<const char*, 7> kActions{"cancel", "pause", "resume", "start", "next", "move", "frame"};
  if (n == 4 && std::find(kActions.begin(), kActions.end(), parts[3]) != kActions.end()) {
    return MatchedRoute{Route::JobAction, job, parts[3]};
  }
  if (n == 5 && is(3, "files")) return MatchedRoute{Route::JobFile, job, parts[4]};
  if (n == 5 && is(3, "sheets")) return MatchedRoute{Route::JobSheet, job, parts[4]};
  return std::nullopt;
}

}  // namespace rotafab::service
