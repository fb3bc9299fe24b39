#include "daemon/service/HttpRoutes.h"

#include <fmt/format.h>

#include <chrono>
#include <regex>
#include <set>

#include "core/ProgramFolders.h"
#include "daemon/service/ApiInput.h"

namespace rotafab::service {
namespace fs = std::filesystem;
using nlohmann::json;

fs::path pageFolder() {
  const fs::path installed = core::installedDataFolder() / "web";
  std::error_code error;
  if (fs::is_directory(installed, error)) return installed;
#if defined(ROTAFAB_WEB_DIR) && defined(ROTAFAB_BUILD_DIR)
  if (fs::equivalent(core::programFolder(), ROTAFAB_BUILD_DIR, error)) return ROTAFAB_WEB_DIR;
#endif
  return "/usr/share/rotafab/web";
}

std::string contentTypeOf(const fs::path& file) {
  const std::string extension = file.extension().string();
  if (extension == ".html") return "text/html; charset=utf-8";
  if (extension == ".js") return "text/javascript; charset=utf-8";
  if (extension == ".css") return "text/css; charset=utf-8";
  if (extension == ".svg") return "image/svg+xml";
  if (extension == ".png") return "image/png";
  if (extension == ".json") return "application/json";
  return "text/plain; charset=utf-8";
}

namespace {

// Of Debian's three.js, only the files the page uses.
const std::set<std::string>& threeFiles() {
  static const std::set<std::string> files{"build/three.min.js", "examples/js/controls/OrbitControls.js"};
  return files;
}

JobId jobNumber(const MatchedRoute& route) {
  const auto id = wholeNumberIn(route.job, kJobField);
  if (!id) throw ApiError(404, fmt::format("no such job: {}", shownText(route.job, 40)));
  return *id;
}

// The workshop page's files and Debian's three.js, the same for everyone.
Reply pageReply(const RouteCall& call) {
  const MatchedRoute& route = call.admitted.route;
  const auto notFound = [&] {
    return ApiError(404, fmt::format("no such page: {} (the page is at /, the API under /api; see docs/API.md)",
                                     call.admitted.target.path()));
  };
  if (route.route == Route::Favicon) {
    Reply none{204, nullptr};  // no icon: asked for by every browser of its own accord
    none.contentType = "image/x-icon";
    return none;
  }
  Reply file;
  if (route.route == Route::PageIndex) {
    file.file = call.pages / "index.html";
  } else if (route.route == Route::PageFile) {
    static const std::regex kPageFile(R"([A-Za-z0-9_-]+\.(html|js|css|svg|png))");
    if (!std::regex_match(route.name, kPageFile)) throw notFound();
    file.file = call.pages / route.name;
  } else {
    if (!threeFiles().contains(route.name)) throw notFound();
    file.file = fs::path(kThreeFolder) / route.name;
  }
  std::error_code error;
  if (!fs::is_regular_file(file.file, error)) {
    throw ApiError(404, fmt::format("{} is not installed (the page's files; see the README)", file.file.string()));
  }
  return file;
}

// A login link's landing: the secret goes to the page in the fragment,
// which the browser never sends to a server; the page keeps it and clears the address.
Reply loginLanding(const RouteCall& call) {
  const auto secret = call.gate.openSession(queryValue(call.admitted.target.query, "code"));
  Reply landing{303, nullptr};
  landing.text = "to the workshop page\n";
  landing.contentType = "text/plain; charset=utf-8";
  landing.headers = {{"Location", secret ? "/#session=" + *secret : "/#signin=used"}};
  return landing;
}

// A one-time link that opens a browser's session for who asks (over the
// Unix socket: this machine's user; over TCP: the token's holder).
Reply loginLink(const RouteCall& call) {
  const Caller& caller = *call.admitted.caller;
  std::string base;
  if (call.overTcp) {
    if (caller.bySession) throw ApiError(403, "a login link is asked for with a token or on this machine");
    base = "http://" + call.host;
  } else {
    if (!call.loopbackPage) {
      throw ApiError(409,
                     "the daemon has no TCP listener on this machine for a browser: add tcp://127.0.0.1:8730 to "
                     "listen in its configuration");
    }
    base = *call.loopbackPage;
  }
  const std::string code = call.gate.newLoginCode(caller.name);
  return {201,
          {{"url", base + "/login?code=" + code},
           {"page", base + "/"},
           {"user", caller.name},
           {"expires_in", std::chrono::seconds(AccessGate::kLoginLinkLasts).count()}}};
}

// {"path": ...} of a mesh or a `make` output folder on the daemon's machine.
Submission jsonSubmission(const RouteCall& call, const json& body) {
  Submission submission;
  submission.owner = call.admitted.caller->name;
  for (const auto& [key, value] : body.items()) {
    if (key != "path" && key != "options" && key != "device" && key != "priority") {
      throw ApiError(400, fmt::format("unknown field \"{}\" (path, options, device, priority)", shownText(key, 40)));
    }
  }
  if (call.overTcp && body.contains("path")) {
    throw ApiError(403,
                   "a path on the daemon's machine can be submitted over its Unix socket only; over TCP, upload "
                   "the mesh (a multipart form with file=@MESH)");
  }
  if (!body.contains("path") || !body["path"].is_string()) {
    throw ApiError(400,
                   "a submission is a multipart upload of the mesh (file=@MESH), or {\"path\": \"/abs/path\"} of a "
                   "mesh or a `make` output folder on the daemon's machine");
  }
  submission.path = checkedText(body["path"], "path", 4096);
  submission.options = makeOptionsOf(body.value("options", json()));
  if (body.contains("device")) submission.device = checkedText(body["device"], "device", 64);
  if (body.contains("priority")) {
    submission.priority = static_cast<int>(wholeNumber(body["priority"], kPriorityField));
  }
  return submission;
}

}  // namespace

void answerRoute(const RouteCall& call, const json& body) {
  Service& service = call.service;
  const MatchedRoute& route = call.admitted.route;
  switch (route.route) {
    case Route::PageIndex:
    case Route::PageFile:
    case Route::PageLibrary:
    case Route::Favicon:
      return call.now(pageReply(call));
    case Route::Login:
      return call.now(loginLanding(call));
    case Route::About:
      return call.now({200, {{"name", "rotafabd"}, {"version", "0.1.0"}, {"host", service.config().host}}});
    case Route::Sessions:
      return call.now(loginLink(call));
    case Route::Devices:
      return service.devices(call.later);
    case Route::Events:
      return;  // (the connection's own)
    case Route::Jobs:
      if (call.get) return service.list(call.later);
      return service.submit(jsonSubmission(call, body), call.later);
    case Route::Job:
      return service.status(jobNumber(route), call.later);
    case Route::JobManifest:
      return service.manifest(jobNumber(route), call.later);
    case Route::JobFile:
      return service.file(jobNumber(route), route.name, call.later);
    case Route::JobSheet: {
      const JobId id = jobNumber(route);
      const auto sheet = wholeNumberIn(route.name, kSheetField);
      if (!sheet) throw ApiError(404, fmt::format("no sheet {}", shownText(route.name, 40)));
      return service.sheet(id, static_cast<int>(*sheet), call.later);
    }
    case Route::JobAction: {
      const JobId id = jobNumber(route);
      return service.act(id, route.name, checkedActionArguments(route.name, body), call.admitted.caller->name,
                         call.later);
    }
  }
}

}  // namespace rotafab::service
