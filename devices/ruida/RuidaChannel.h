#pragma once
// The two ways to reach a Ruida controller, behind one interface: UDP
// (ruida://HOST), where each packet carries a 16-bit checksum of its
// swizzled bytes and the controller answers it with one swizzled byte, ACK
// or NAK (send it again), one packet in flight; and its USB port, a serial
// device (ruida+serial://), where the same swizzled stream goes without
// checksums or answers. Both read the controller's memory (DA 00 address:
// its status, position, bed size, card ID) the same way. A controller that
// stops answering is a DeviceFault Timeout naming the host and the packet,
// after a bounded number of sends: never a hang.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "devices/Device.h"
#include "devices/ruida/RuidaCodec.h"
#include "devices/transport/DatagramLink.h"
#include "devices/transport/SerialLink.h"

namespace rotafab::devices::ruida {

struct RuidaTimeouts {
  Millis reply{500};   // for the answer to one packet or memory read
  int sends = 6;       // sends of one packet without an answer before the controller is given up
  int refusals = 20;   // NAKs of one packet in a row before the link is given up
  Millis poll{100};    // between status reads while a job runs
  Millis stop{10000};  // after a stop: for the controller to report its job ended
};

// The controller's memory, as DA 00 reads it (two 7-bit bytes each).
inline constexpr uint16_t kMemoryStatus = 0x0400;                // bit 0: a job runs; bit 24: the head moves
inline constexpr uint16_t kMemoryX = 0x0421, kMemoryY = 0x0431;  // the head, micrometres
inline constexpr uint16_t kMemoryBedX = 0x0026, kMemoryBedY = 0x0036;
inline constexpr uint16_t kMemoryCardId = 0x057E;
inline constexpr int64_t kStatusJobRuns = 0x01, kStatusMoving = 0x01000000;

class RuidaChannel {
 public:
  virtual ~RuidaChannel() = default;
  // Sends whole commands (logical bytes, at most maxPacket() of them) and
  // returns once the controller has taken them.
  virtual void send(const Bytes& commands) = 0;
  // The value at a memory address.
  virtual int64_t read(uint16_t address) = 0;
  [[nodiscard]] virtual std::string name() const = 0;
  // A packet's commands, at most: with its 2-byte sum, 1,472 bytes, a UDP
  // payload that one 1,500-byte Ethernet frame carries unfragmented.
  [[nodiscard]] virtual size_t maxPacket() const { return 1470; }
  // Packets sent again (a NAK, or no answer in time), since opened.
  [[nodiscard]] virtual size_t resends() const { return 0; }
  [[nodiscard]] virtual size_t packets() const { return 0; }
};

// Cuts a stream into packets of at most `limit` bytes at command boundaries.
std::vector<Bytes> packetsOf(const Bytes& stream, size_t limit);

std::unique_ptr<RuidaChannel> udpChannel(std::unique_ptr<DatagramLink> link, uint8_t magic,
                                         RuidaTimeouts timeouts = {});
std::unique_ptr<RuidaChannel> serialChannel(std::unique_ptr<Link> link, uint8_t magic, RuidaTimeouts timeouts = {});

}  // namespace rotafab::devices::ruida
