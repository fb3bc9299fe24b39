#pragma once
// The daemon's configuration (docs/CONTRACT.md, "Daemon"): `rotafabd --config FILE`,
// YAML, validated as the profiles are (one line, "FILE:LINE:COL: key: what
// is wrong"), every key optional. With no file at all the daemon runs with
// the defaults: state in $XDG_STATE_HOME/rotafab (else
// ~/.local/state/rotafab), one simulated GRBL, the Unix socket.

#include <filesystem>
#include <optional>
#include <string>

#include <vector>
#include "daemon/service/NotifyConfig.h"

#include "core/LengthUnit.h"
#include "core/ProgramFolders.h"

namespace rotafab::service {

// The workshop page's port on loopback by default (docs/CONTRACT.md, "Daemon").
constexpr int kPagePort = 8730;

struct DeviceConfig {
  std::string name;                      // how people and the API call it: "laser1"
  std::string machine;                   // its machine profile: what jobs for it are planned against
  std::string uri;                       // a device URI (docs/CONTRACT.md, "Devices")
  std::string material = "posterboard";  // the power and speed overrides its jobs are cut with
  bool autoStart = false;                // cut a job once planned, with no operator's `start`
};

struct TokenConfig {
  std::string name;  // who holds it: the owner of what they submit
  std::string hash;  // "sha256$SALT$HEX" (hashToken())
};

struct DaemonConfig {
  std::filesystem::path file;  // the file it was read from; empty: the defaults
  std::filesystem::path stateDir;
  // Where the jobs are kept: empty for SQLite in stateDir (the default), or
  // a PostgreSQL URI (postgresql://USER@HOST:PORT/DB).
  std::string store;
  std::string host;  // this daemon's name (default: the host name); its own on a shared store
  // Where uploaded meshes and planned sheets are kept: empty for `spool` in
  // stateDir; on a shared store, a directory every host mounts at this path.
  std::filesystem::path spool;
  // Seconds a host on a shared store is taken to be alive after its last
  // heartbeat (renewed five times within it); once it runs out, another
  // host releases its jobs (a cut interrupted, a plan made again).
  double lease = 10;
  // "unix:PATH" and "tcp://HOST:PORT"; the first Unix one is where `rotafab` looks.
  std::vector<std::string> listen;
  // The listeners are the defaults: the socket, and loopback TCP for the
  // workshop page on kPagePort, or on any free port when another program has it.
  bool defaultListen = true;
  std::vector<TokenConfig> tokens;
  // Where browsers reach the page other than at a listener's own address:
  // a reverse proxy's ("https://rotafab.lab.example"). A request that
  // changes something is taken from a page of these origins or of the
  // listener's own, and a loopback listener answers to their host names.
  std::vector<std::string> origins;
  std::vector<DeviceConfig> devices;
  size_t uploadLimit = 256u << 20;  // bytes of one request's body
  // Connections at once, on the Unix socket and on TCP each (of TCP's, half
  // at most before a request shows a token or session; HttpServer.cpp).
  size_t connectionLimit = 64;
  double headerTimeout = 10;  // seconds for a request's header to arrive
  double bodyTimeout = 120;   // seconds for its body
  unsigned planners = 1;      // jobs planned at once (each on every core)
  double planTimeout = 3600;  // seconds a plan may take before its job fails
  NotifyConfig notify;        // webhooks and an MQTT broker told of the operator's events
  // The unit the page and `rotafab status` show a job's lengths in, unless
  // the job says its own (make's --units): `units: mm` or `in`.
  std::optional<core::LengthUnit> units;
};

using core::defaultSocket;  // (core/ProgramFolders.h: the command line finds the socket too)
using core::defaultStateDir;

// The defaults: what the daemon runs with when no file is given.
DaemonConfig defaultConfig();

// Reads `file`; throws ConfigError (one line, FILE:LINE:COL: key: what is wrong).
DaemonConfig loadConfig(const std::filesystem::path& file);

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A token's salted hash as the configuration keeps it: "sha256$SALT$HEX".
std::string hashToken(const std::string& token, const std::string& salt);
// Whether `token` is the one `hash` was made from; compares in constant time.
bool tokenMatches(const std::string& token, const std::string& hash);

}  // namespace rotafab::service
