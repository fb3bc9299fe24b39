#include "devices/ruida/RuidaChannel.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <optional>

namespace rotafab::devices::ruida {
namespace {

using Clock = std::chrono::steady_clock;

Bytes memoryRead(uint16_t address) {
  return {0xDA, 0x00, static_cast<uint8_t>(address >> 8), static_cast<uint8_t>(address & 0x7F)};
}

// The value of a memory read's reply (DA 01 address value), if that is what `reply` is.
std::optional<int64_t> memoryValue(const Bytes& reply, uint16_t address) {
  const Bytes want = {0xDA, 0x01, static_cast<uint8_t>(address >> 8), static_cast<uint8_t>(address & 0x7F)};
  if (reply.size() < 9 || !std::equal(want.begin(), want.end(), reply.begin())) return std::nullopt;
  // Operand bytes are 7-bit: one with its top bit set is a reply cut short.
  if (std::any_of(reply.begin() + 4, reply.begin() + 9, [](uint8_t b) { return b & 0x80; })) return std::nullopt;
  return readU35(reply.data() + 4);
}

std::string describe(const Bytes& commands) {
  return commands.empty() ? std::string("an empty packet")
                          : fmt::format("the packet of {} bytes from command {:02X}", commands.size(), commands[0]);
}

class UdpChannel : public RuidaChannel {
 public:
  UdpChannel(std::unique_ptr<DatagramLink> link, uint8_t magic, RuidaTimeouts timeouts)
      : link_(std::move(link)), swizzle_(magic), timeouts_(timeouts) {}

  void send(const Bytes& commands) override { exchange(commands, std::nullopt); }

  int64_t read(uint16_t address) override { return *exchange(memoryRead(address), address); }

  [[nodiscard]] std::string name() const override { return "ruida://" + link_->name(); }
  [[nodiscard]] size_t resends() const override { return resends_; }
  [[nodiscard]] size_t packets() const override { return packets_; }

 private:
  // Sends one packet until the controller takes it (and, for a memory
  // read, answers it); the value read, if one was asked for.
  std::optional<int64_t> exchange(const Bytes& commands, std::optional<uint16_t> address) {
    const Bytes packet = udpPacket(swizzle_(commands));
    const uint8_t ack = swizzle_(kAck), nak = swizzle_(kNak), error = swizzle_(kError);
    int silent = 0, refused = 0;
    // The first one-byte answer to each send that this magic does not
    // read: the same each time, it is an ACK in the controller's own magic.
    std::optional<uint8_t> foreign;
    bool sameEachTime = true;
    // Late answers to earlier packets would be taken for this one's.
    link_->drain();
    for (;;) {
      link_->send(packet);
      ++packets_;
      bool nakked = false, answered = false;
      const auto until = Clock::now() + timeouts_.reply;
      for (;;) {
        const auto left = std::chrono::duration_cast<Millis>(until - Clock::now());
        const auto reply = link_->receive(std::max(left, Millis(0)));
        if (!reply) break;
        if (reply->size() == 1) {  // swizzled, without a checksum
          const uint8_t answer = (*reply)[0];
          if (answer == ack) {
            if (!address) return std::nullopt;
            continue;  // the value comes in a datagram of its own
          }
          if (answer == nak || answer == error) {
            if (++refused >= timeouts_.refusals) {
              throw DeviceFault(FaultKind::Protocol,
                                fmt::format("{}: the controller refused {} {} times in a row (a NAK each time): "
                                            "check the network and the magic number (?magic=)",
                                            name(), describe(commands), refused));
            }
            nakked = true;
            break;
          }
          if (!answered && answer != swizzle_(kEnquire)) {
            sameEachTime = sameEachTime && (!foreign || *foreign == answer);
            foreign = answer;
          }
          answered = true;
          continue;  // a keep-alive (ENQ), a late answer to an earlier packet, or one in another magic
        }
        if (address) {
          if (const auto value = memoryValue(swizzle_.undo(*reply), *address)) return value;
        }
      }
      // No answer in time (the packet or its answer lost): send it again, a bounded number of times.
      if (!nakked && ++silent >= timeouts_.sends) {
        if (foreign && sameEachTime) {
          // (byte - 1) XOR the ACK with its bits 7 and 0 swapped: the magic in which `byte` is an ACK.
          const auto swappedAck = static_cast<uint8_t>(Swizzle(0)(kAck) - 1);
          const auto magic = static_cast<uint8_t>(static_cast<uint8_t>(*foreign - 1) ^ swappedAck);
          throw DeviceFault(FaultKind::Refused,
                            fmt::format("{}: the controller answers each packet with 0x{:02X}, which is no answer in "
                                        "magic number 0x{:02X} but an ACK in 0x{:02X}: add ?magic=0x{:02X} to its URI",
                                        name(), *foreign, swizzle_.magic(), magic, magic));
        }
        throw DeviceFault(FaultKind::Timeout,
                          fmt::format("{}: the controller stopped answering: no answer to {} in {} sends of {} ms "
                                      "each (packet {})",
                                      name(), describe(commands), silent, timeouts_.reply.count(), packets_));
      }
      ++resends_;
    }
  }

  std::unique_ptr<DatagramLink> link_;
  Swizzle swizzle_;
  RuidaTimeouts timeouts_;
  size_t resends_ = 0, packets_ = 0;
};

class SerialChannel : public RuidaChannel {
 public:
  SerialChannel(std::unique_ptr<Link> link, uint8_t magic, RuidaTimeouts timeouts)
      : link_(std::move(link)), swizzle_(magic), timeouts_(timeouts) {}

  void send(const Bytes& commands) override {
    const Bytes wire = swizzle_(commands);
    link_->write(std::string(wire.begin(), wire.end()), timeouts_.reply * timeouts_.sends);
    ++packets_;
  }

  int64_t read(uint16_t address) override {
    Bytes got;  // kept across tries: a reply may come late, after the next request went
    for (int sent = 1;; ++sent) {
      send(memoryRead(address));
      const auto until = Clock::now() + timeouts_.reply;
      for (;;) {
        const auto left = std::chrono::duration_cast<Millis>(until - Clock::now());
        const auto some = left.count() > 0 ? link_->readSome(left) : std::nullopt;
        if (!some) break;
        const Bytes more = swizzle_.undo(Bytes(some->begin(), some->end()));
        got.insert(got.end(), more.begin(), more.end());
        // The reply starts at its DA; anything before it is from before.
        for (;;) {
          while (!got.empty() && got[0] != 0xDA) got.erase(got.begin());
          if (got.size() < 9) break;
          if (const auto value = memoryValue(got, address)) return *value;
          got.erase(got.begin());
        }
      }
      if (sent >= timeouts_.sends) {
        throw DeviceFault(FaultKind::Timeout,
                          fmt::format("{}: the controller stopped answering: no reply to memory read {:04X} in {} "
                                      "tries of {} ms each",
                                      name(), address, sent, timeouts_.reply.count()));
      }
    }
  }

  [[nodiscard]] std::string name() const override { return "ruida+serial://" + link_->name(); }
  [[nodiscard]] size_t packets() const override { return packets_; }

 private:
  std::unique_ptr<Link> link_;
  Swizzle swizzle_;
  RuidaTimeouts timeouts_;
  size_t packets_ = 0;
};

}  // namespace

std::vector<Bytes> packetsOf(const Bytes& stream, size_t limit) {
  std::vector<Bytes> packets;
  Bytes packet;
  for (const Bytes& command : splitCommands(stream)) {
    if (!packet.empty() && packet.size() + command.size() > limit) packets.push_back(std::exchange(packet, {}));
    packet.insert(packet.end(), command.begin(), command.end());
  }
  if (!packet.empty()) packets.push_back(std::move(packet));
  return packets;
}

std::unique_ptr<RuidaChannel> udpChannel(std::unique_ptr<DatagramLink> link, uint8_t magic, RuidaTimeouts timeouts) {
  return std::make_unique<UdpChannel>(std::move(link), magic, timeouts);
}

std::unique_ptr<RuidaChannel> serialChannel(std::unique_ptr<Link> link, uint8_t magic, RuidaTimeouts timeouts) {
  return std::make_unique<SerialChannel>(std::move(link), magic, timeouts);
}

}  // namespace rotafab::devices::ruida
