// libFuzzer target: the daemon's edge, whatever a client sends. The bytes are
// a request as they arrive on a connection: Beast reads its header (with the
// daemon's limit), the gate (AccessGate.h) admits or refuses it from that
// header alone, and an admitted body is read as the daemon reads it: a JSON
// action's arguments checked (ApiInput.h), or a multipart form fed to the
// streaming reader in pieces (Multipart.h). A refusal is an ApiError or a
// malformed form's std::invalid_argument; anything else (a crash, a
// sanitizer report, another exception, a hang) is a finding.
// The first byte picks the listener (Unix socket, loopback or other TCP) and
// the size of the pieces the body arrives in.

#include <boost/beast/http.hpp>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "daemon/service/AccessGate.h"
#include "daemon/service/ApiError.h"
#include "daemon/service/ApiInput.h"
#include "daemon/service/DaemonConfig.h"
#include "daemon/service/Multipart.h"

namespace http = boost::beast::http;
using namespace rotafab::service;

namespace {

struct Discard : MultipartReader::Parts {
  void begin(const FormPartHead& head) override {
    if (head.fileName) (void)cleanFileName(*head.fileName);
  }
  void bytes(std::string_view) override {}
  void end() override {}
};

AccessGate& gate() {
  static DaemonConfig config = [] {
    DaemonConfig made;
    made.tokens.push_back({"alice", hashToken("fuzz-token", "5a17")});
    made.origins.push_back("https://rotafab.lab.example");
    made.uploadLimit = 1 << 20;
    return made;
  }();
  static AccessGate made(config);
  return made;
}

void readBody(const Admission& admitted, std::string_view body, size_t piece) {
  if (admitted.body == BodyKind::JsonOrForm) {
    Discard parts;
    MultipartReader reader(admitted.boundary, parts);
    for (size_t at = 0; at < body.size(); at += piece) reader.feed(body.substr(at, piece));
    reader.finish();
  } else if (admitted.body == BodyKind::Json) {
    const nlohmann::json value = nlohmann::json::parse(body, nullptr, false);
    if (value.is_discarded()) return;
    if (admitted.route.route == Route::JobAction) (void)checkedActionArguments(admitted.route.name, value);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const uint8_t how = data[0];
  const std::string_view bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  const Listener listener{(how & 3) == 0, (how & 3) == 1};
  const size_t piece = 1 + (how >> 2) * 37;

  http::request_parser<http::empty_body> parser;
  parser.header_limit(16 * 1024);
  parser.eager(false);
  boost::beast::error_code error;
  const size_t used = parser.put(boost::asio::buffer(bytes.data(), bytes.size()), error);
  if (error || !parser.is_header_done()) return 0;
  const RequestHead head = requestHead(parser);
  try {
    const std::optional<Caller> peer =
        listener.unixSocket ? std::optional<Caller>(Caller{"root", false}) : std::nullopt;
    const Admission admitted = gate().admit(head, listener, peer);
    (void)withoutDaemonPaths(std::string(admitted.target.path()), {"/var/lib/rotafab", "/api"});
    (void)queryValue(admitted.target.query, "session");
    std::string_view body = bytes.substr(used);
    if (body.size() > admitted.bodyLimit) body = body.substr(0, admitted.bodyLimit);
    readBody(admitted, body, piece);
  } catch (const ApiError& refused) {
    if (refused.status < 400 || refused.status > 599) std::abort();
  } catch (const std::invalid_argument&) {
    // A malformed form, said as the daemon says it.
  }
  return 0;
}
