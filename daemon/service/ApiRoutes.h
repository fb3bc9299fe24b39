#pragma once
// The daemon's routes (docs/API.md) and, in one table, what each takes:
// its methods, its body, and whether it is served to a caller nobody knows.
// The gate (AccessGate.h) and the server (HttpServer.cpp) both read them
// from here, on the path as RequestTarget.h normalises it.

#include <boost/beast/http/verb.hpp>
#include <optional>
#include <string>
#include <vector>

namespace rotafab::service {

enum class Route {
  // The workshop page.
  PageIndex,    // /
  PageFile,     // /app/NAME
  PageLibrary,  // /lib/three/PATH (Debian's three.js)
  Login,        // /login?code=CODE, a one-time login link's landing
  Favicon,      // /favicon.ico
  // The API.
  About,        // /api
  Sessions,     // /api/sessions
  Devices,      // /api/devices
  Events,       // /api/events
  Jobs,         // /api/jobs
  Job,          // /api/jobs/ID
  JobManifest,  // /api/jobs/ID/manifest
  JobFile,      // /api/jobs/ID/files/NAME
  JobSheet,     // /api/jobs/ID/sheets/N
  JobAction,    // /api/jobs/ID/{cancel,pause,resume,start,next,move}
};

// What a request's body may be.
enum class BodyKind {
  None,        // no body at all
  Json,        // a JSON object (Content-Type: application/json), at most kJsonBodyLimit bytes
  JsonOrForm,  // that, or a multipart form with the mesh (at most the configuration's upload_limit)
};

constexpr size_t kJsonBodyLimit = 64 * 1024;

struct Endpoint {
  Route route;
  boost::beast::http::verb method;
  bool open;  // served without a caller the gate knows
  BodyKind body;
};

// Every route and method the daemon answers; a pair not here is refused (405).
const std::vector<Endpoint>& endpoints();
const Endpoint* endpointFor(Route route, boost::beast::http::verb method);
// The methods a route takes, for a 405's message: "GET and POST".
std::string methodsOf(Route route);

struct MatchedRoute {
  Route route;
  std::string job;   // ID, as it was written
  std::string name;  // the page's file, the library's path, the job's file, sheet or action
};

// The route of a normalised path; none when it names nothing the daemon serves.
std::optional<MatchedRoute> matchRoute(const std::vector<std::string>& parts);

}  // namespace rotafab::service
