#include "devices/ruida/RuidaDiscovery.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>

#include "devices/ruida/RuidaChannel.h"

namespace rotafab::devices::ruida {

std::vector<FoundController> probeControllers(const std::string& target, uint16_t port, uint16_t localPort, Millis wait,
                                              uint8_t magic) {
  std::vector<FoundController> found;
  const int s = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (s < 0) return found;
  const int yes = 1;
  ::setsockopt(s, SOL_SOCKET, SO_BROADCAST, &yes, sizeof yes);
  sockaddr_in local{}, to{};
  local.sin_family = AF_INET;
  local.sin_port = htons(localPort);
  to.sin_family = AF_INET;
  to.sin_port = htons(port);
  const Swizzle swizzle(magic);
  const Bytes ask = {0xDA, 0x00, static_cast<uint8_t>(kMemoryCardId >> 8), static_cast<uint8_t>(kMemoryCardId & 0x7F)};
  const Bytes packet = udpPacket(swizzle(ask));
  if (::inet_pton(AF_INET, target.c_str(), &to.sin_addr) != 1 ||
      ::bind(s, reinterpret_cast<sockaddr*>(&local), sizeof local) != 0 ||
      ::sendto(s, packet.data(), packet.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to) < 0) {
    ::close(s);
    return found;
  }
  const auto until = std::chrono::steady_clock::now() + wait;
  for (;;) {
    const auto left = std::chrono::duration_cast<Millis>(until - std::chrono::steady_clock::now()).count();
    pollfd ready{s, POLLIN, 0};
    if (left <= 0 || ::poll(&ready, 1, static_cast<int>(left)) <= 0) break;
    uint8_t buffer[64];
    sockaddr_in from{};
    socklen_t length = sizeof from;
    const ssize_t got = ::recvfrom(s, buffer, sizeof buffer, 0, reinterpret_cast<sockaddr*>(&from), &length);
    if (got <= 0) continue;
    char text[INET_ADDRSTRLEN] = {};
    ::inet_ntop(AF_INET, &from.sin_addr, text, sizeof text);
    const Bytes reply = swizzle.undo(Bytes(buffer, buffer + got));
    const bool ack = got == 1 && reply[0] == kAck;
    const bool card = got >= 9 && reply[0] == 0xDA && reply[1] == 0x01 && reply[2] == ask[2] && reply[3] == ask[3];
    if (!ack && !card) continue;  // not a Ruida's answer
    auto it = std::find_if(found.begin(), found.end(), [&](const FoundController& c) { return c.address == text; });
    if (it == found.end()) it = found.insert(found.end(), {text, 0});
    if (card) it->card = readU35(reply.data() + 4);
  }
  ::close(s);
  return found;
}

}  // namespace rotafab::devices::ruida
