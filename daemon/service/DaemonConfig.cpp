#include "daemon/service/DaemonConfig.h"

#include <fmt/format.h>
#include <openssl/crypto.h>
#include <openssl/sha.h>
#include <unistd.h>

#include <cctype>
#include <cstdlib>

#include "profiles/YamlReader.h"

namespace rotafab::service {
namespace fs = std::filesystem;
namespace {

using core::environmentValue;

fs::path home() { return core::homeFolder(); }

// `~/` and `$XDG_RUNTIME_DIR`, `$XDG_STATE_HOME`, `$HOME` at the start of a path.
fs::path expanded(const std::string& text) {
  if (text.starts_with("~/")) return home() / text.substr(2);
  if (text.starts_with("$")) {
    const size_t slash = text.find('/');
    const std::string name = text.substr(1, slash == std::string::npos ? std::string::npos : slash - 1);
    const std::string value = environmentValue(name.c_str());
    if (!value.empty()) return fs::path(value) / (slash == std::string::npos ? "" : text.substr(slash + 1));
  }
  return text;
}

std::string hostName() {
  char name[256] = {};
  if (::gethostname(name, sizeof name - 1) != 0) return "localhost";
  std::string host = name;
  // (As a spool entry's name may hold it.)
  for (char& c : host) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '-') c = '_';
  }
  return host.empty() ? "localhost" : host;
}

std::string hex(const unsigned char* bytes, size_t size) {
  std::string text;
  for (size_t i = 0; i < size; ++i) text += fmt::format("{:02x}", bytes[i]);
  return text;
}

// A listen address: unix:PATH or tcp://HOST:PORT.
bool validListen(const std::string& address) {
  if (address.starts_with("unix:")) return address.size() > 5;
  if (!address.starts_with("tcp://")) return false;
  const std::string rest = address.substr(6);
  const size_t colon = rest.rfind(':');
  if (colon == std::string::npos || colon == 0) return false;
  const std::string port = rest.substr(colon + 1);
  if (port.empty() || port.size() > 5 || port.find_first_not_of("0123456789") != std::string::npos) return false;
  return std::stoi(port) < 65536;
}

// The devices a configuration lists (`devices:`), each checked.
std::vector<DeviceConfig> readDevices(const profiles::YamlReader& reader, const YAML::Node& devices) {
  if (!devices.IsSequence()) reader.fail(devices, "devices", "expected a list of {name, machine, uri, auto_start}");
  std::vector<DeviceConfig> read;
  for (size_t i = 0; i < devices.size(); ++i) {
    const std::string key = fmt::format("devices[{}]", i);
    reader.keys(devices[i], key, {"name", "machine", "uri", "material", "auto_start"}, {"name", "uri"});
    DeviceConfig device;
    device.name = reader.text(devices[i]["name"], key + ".name");
    if (device.name.empty() || device.name.find_first_of(" /?#") != std::string::npos) {
      reader.fail(devices[i]["name"], key + ".name", "expected a name without spaces or slashes, such as laser1");
    }
    for (const DeviceConfig& other : read) {
      if (other.name == device.name) reader.fail(devices[i]["name"], key + ".name", "another device has this name");
    }
    device.uri = reader.text(devices[i]["uri"], key + ".uri");
    device.machine = devices[i]["machine"] ? reader.text(devices[i]["machine"], key + ".machine") : "";
    if (devices[i]["material"]) device.material = reader.text(devices[i]["material"], key + ".material");
    if (devices[i]["auto_start"]) device.autoStart = reader.boolean(devices[i]["auto_start"], key + ".auto_start");
    read.push_back(std::move(device));
  }
  return read;
}

// The limits of requests and plans, and the unit lengths are shown in.
void readLimits(const profiles::YamlReader& reader, const YAML::Node& root, DaemonConfig& config) {
  if (root["upload_limit"]) {
    config.uploadLimit = static_cast<size_t>(reader.integer(root["upload_limit"], "upload_limit", 1, 1 << 30));
  }
  if (root["connection_limit"]) {
    config.connectionLimit =
        static_cast<size_t>(reader.integer(root["connection_limit"], "connection_limit", 1, 10000));
  }
  if (root["header_timeout"]) config.headerTimeout = reader.number(root["header_timeout"], "header_timeout", 0.1, 3600);
  if (root["body_timeout"]) config.bodyTimeout = reader.number(root["body_timeout"], "body_timeout", 0.1, 86400);
  if (root["plan_timeout"]) config.planTimeout = reader.number(root["plan_timeout"], "plan_timeout", 1, 7 * 86400);
  if (root["planners"]) config.planners = static_cast<unsigned>(reader.integer(root["planners"], "planners", 1, 64));
  if (root["units"]) config.units = reader.shownUnit(root["units"], "units");
}

}  // namespace

// The Unix socket for `rotafab`, and loopback TCP for a browser (the workshop page).
static std::vector<std::string> defaultListen(const fs::path& stateDir) {
  return {"unix:" + defaultSocket(stateDir).string(), fmt::format("tcp://127.0.0.1:{}", kPagePort)};
}

DaemonConfig defaultConfig() {
  DaemonConfig config;
  config.stateDir = defaultStateDir();
  config.host = hostName();
  config.listen = defaultListen(config.stateDir);
  // A simulated GRBL that runs 100 times faster than the machine it stands
  // for, so that a first job is seen through to its end; progress is said in real time.
  config.devices = {{"laser1", "grbl-diode-400", "sim:grbl?speed=100", "posterboard", false}};
  return config;
}

DaemonConfig loadConfig(const fs::path& file) {
  DaemonConfig config = defaultConfig();
  config.file = file;
  const profiles::YamlReader reader(file);
  YAML::Node root;
  try {
    root = reader.load("config", "expected a map of keys (state_dir, listen, devices, ...)", true);
  } catch (const profiles::ProfileError& error) {
    throw ConfigError(error.what());
  }
  try {
    const auto keys = reader.keys(
        root, "",
        {"state_dir", "store", "host", "spool", "lease", "listen", "tokens", "origins", "devices", "upload_limit",
         "connection_limit", "planners", "header_timeout", "body_timeout", "plan_timeout", "notify", "units"},
        {});
    bool listenGiven = false;
    if (root["state_dir"]) config.stateDir = expanded(reader.text(root["state_dir"], "state_dir"));
    if (root["store"]) {
      const std::string store = reader.text(root["store"], "store");
      if (store.starts_with("postgresql://") || store.starts_with("postgres://")) {
        config.store = store;
      } else if (store != "sqlite") {
        reader.fail(root["store"], "store",
                    fmt::format("expected sqlite or postgresql://USER@HOST:PORT/DB, found '{}'", store));
      }
    }
    if (root["host"]) {
      config.host = reader.text(root["host"], "host");
      if (config.host.empty() || config.host.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                                               "0123456789._-") != std::string::npos) {
        reader.fail(root["host"], "host",
                    "expected a name of letters, digits, '.', '_' and '-', such as cutter-room-2");
      }
    }
    if (root["spool"]) config.spool = expanded(reader.text(root["spool"], "spool"));
    if (root["lease"]) config.lease = reader.number(root["lease"], "lease", 1, 3600);
    if (const YAML::Node listen = root["listen"]) {
      if (!listen.IsSequence())
        reader.fail(listen, "listen", "expected a list such as [unix:/run/rotafab.sock, tcp://127.0.0.1:8730]");
      config.listen.clear();
      config.defaultListen = false;
      listenGiven = true;
      for (size_t i = 0; i < listen.size(); ++i) {
        const std::string key = fmt::format("listen[{}]", i);
        const std::string address = reader.text(listen[i], key);
        if (!validListen(address)) {
          reader.fail(listen[i], key, fmt::format("expected unix:PATH or tcp://HOST:PORT, found '{}'", address));
        }
        config.listen.push_back(address.starts_with("unix:") ? "unix:" + expanded(address.substr(5)).string()
                                                             : address);
      }
    }
    if (const YAML::Node notify = root["notify"]) {
      reader.keys(notify, "notify", {"webhooks", "mqtt", "topic"}, {});
      if (const YAML::Node hooks = notify["webhooks"]) {
        if (!hooks.IsSequence())
          reader.fail(hooks, "notify.webhooks", "expected a list such as [http://HOST:PORT/PATH]");
        for (size_t i = 0; i < hooks.size(); ++i) {
          const std::string key = fmt::format("notify.webhooks[{}]", i);
          const std::string url = reader.text(hooks[i], key);
          try {
            webhookEndpoint(url);
          } catch (const std::invalid_argument& error) {
            reader.fail(hooks[i], key, error.what());
          }
          config.notify.webhooks.push_back(url);
        }
      }
      if (notify["mqtt"]) {
        config.notify.mqtt = reader.text(notify["mqtt"], "notify.mqtt");
        try {
          mqttEndpoint(config.notify.mqtt);
        } catch (const std::invalid_argument& error) {
          reader.fail(notify["mqtt"], "notify.mqtt", error.what());
        }
      }
      if (notify["topic"]) {
        config.notify.topic = reader.text(notify["topic"], "notify.topic");
        if (config.notify.topic.empty() || config.notify.topic.find_first_of("#+") != std::string::npos ||
            config.notify.topic.ends_with("/")) {
          reader.fail(notify["topic"], "notify.topic",
                      "expected a topic such as rotafab or lab/lasers, without # or +");
        }
      }
    }
    if (const YAML::Node tokens = root["tokens"]) {
      if (!tokens.IsSequence())
        reader.fail(tokens, "tokens", "expected a list of {name: ..., hash: \"sha256$SALT$HEX\"}");
      for (size_t i = 0; i < tokens.size(); ++i) {
        const std::string key = fmt::format("tokens[{}]", i);
        reader.keys(tokens[i], key, {"name", "hash"}, {"name", "hash"});
        TokenConfig token{reader.text(tokens[i]["name"], key + ".name"), reader.text(tokens[i]["hash"], key + ".hash")};
        const size_t first = token.hash.find('$'), second = token.hash.rfind('$');
        if (!token.hash.starts_with("sha256$") || first == second || token.hash.size() - second - 1 != 64) {
          reader.fail(tokens[i]["hash"], key + ".hash",
                      "expected \"sha256$SALT$HEX\" (64 hex digits), as `rotafabd --hash-token` prints it");
        }
        config.tokens.push_back(std::move(token));
      }
    }
    if (const YAML::Node origins = root["origins"]) {
      if (!origins.IsSequence())
        reader.fail(origins, "origins", "expected a list such as [https://rotafab.lab.example]");
      for (size_t i = 0; i < origins.size(); ++i) {
        const std::string key = fmt::format("origins[{}]", i);
        std::string origin = reader.text(origins[i], key);
        while (origin.ends_with("/")) origin.pop_back();
        const size_t scheme = origin.find("://");
        const bool web = origin.starts_with("https://") || origin.starts_with("http://");
        if (!web || origin.size() == scheme + 3 || origin.find_first_of("/?#@ ", scheme + 3) != std::string::npos) {
          reader.fail(origins[i], key,
                      fmt::format("expected the page's address as a browser shows it, scheme and host (and port), "
                                  "such as https://rotafab.lab.example; found '{}'",
                                  origin));
        }
        config.origins.push_back(origin);
      }
    }
    if (const YAML::Node devices = root["devices"]) config.devices = readDevices(reader, devices);
    readLimits(reader, root, config);
    if (!listenGiven && root["state_dir"]) config.listen = defaultListen(config.stateDir);
    // A listener beyond this machine needs a token to let anyone in.
    for (size_t i = 0; i < config.listen.size(); ++i) {
      const std::string& address = config.listen[i];
      if (!address.starts_with("tcp://")) continue;
      const std::string host = address.substr(6, address.rfind(':') - 6);
      const bool loopback = host == "127.0.0.1" || host == "localhost" || host == "[::1]" || host == "::1";
      if (!loopback && config.tokens.empty()) {
        reader.fail(root["listen"][i], fmt::format("listen[{}]", i),
                    fmt::format("{} is reachable from other machines: give tokens (rotafabd --hash-token)", address));
      }
    }
    (void)keys;
  } catch (const profiles::ProfileError& error) {
    throw ConfigError(error.what());
  }
  return config;
}

std::string hashToken(const std::string& token, const std::string& salt) {
  const std::string salted = salt + token;
  unsigned char digest[SHA256_DIGEST_LENGTH];
  SHA256(reinterpret_cast<const unsigned char*>(salted.data()), salted.size(), digest);
  return fmt::format("sha256${}${}", salt, hex(digest, sizeof digest));
}

bool tokenMatches(const std::string& token, const std::string& hash) {
  const size_t first = hash.find('$'), second = hash.rfind('$');
  if (first == std::string::npos || first == second) return false;
  const std::string expected = hashToken(token, hash.substr(first + 1, second - first - 1));
  if (expected.size() != hash.size()) return false;
  return CRYPTO_memcmp(expected.data(), hash.data(), hash.size()) == 0;
}

}  // namespace rotafab::service
