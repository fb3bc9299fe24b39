#pragma once
// What each route the gate admitted answers (docs/API.md): the API's calls
// handed to the service, the page's files, the login link and its landing.
// The connection (HttpServer.cpp) reads the request and sends the reply;
// what a request means is decided here, the same for both listeners but
// for what only the Unix socket may do.

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "daemon/service/AccessGate.h"
#include "daemon/service/Service.h"

namespace rotafab::service {

// One admitted request, as the routes need it.
struct RouteCall {
  Service& service;
  AccessGate& gate;
  const Admission& admitted;
  bool get = false;      // GET, else the route's other method
  bool overTcp = false;  // else the Unix socket
  std::string host;      // the request's Host (a TCP login link is made on it)
  // Where a browser on this machine reaches the daemon (its loopback TCP listener), if it has one.
  std::optional<std::string> loopbackPage;
  std::filesystem::path pages;  // the page's files
  // A reply known at once, and the handler of one the service gives later (on any thread).
  std::function<void(Reply)> now;
  ReplyHandler later;
};

// Answers every route but the event stream (which the connection keeps).
// Throws ApiError (4xx), and what the service's input checks throw.
void answerRoute(const RouteCall& call, const nlohmann::json& body);

// The folder of the workshop page's files: PREFIX/share/rotafab/web once
// installed; the source tree's daemon/web for a program run from its build tree.
std::filesystem::path pageFolder();
// Debian's libjs-three, which the page's 3D view loads.
inline constexpr std::string_view kThreeFolder = "/usr/share/javascript/three";
// A served file's Content-Type, by its name.
std::string contentTypeOf(const std::filesystem::path& file);

}  // namespace rotafab::service
