#include "devices/ruida/RuidaCodec.h"

#include <algorithm>
#include <cmath>

namespace rotafab::devices::ruida {
namespace {

uint8_t swapEnds(uint8_t byte) {
  return static_cast<uint8_t>((byte & 0x7E) | ((byte & 0x01) << 7) | ((byte & 0x80) >> 7));
}

constexpr int kFullPower = 0x3FFF;

}  // namespace

Swizzle::Swizzle(uint8_t magic) : magic_(magic) {
  for (int b = 0; b < 256; ++b) {
    const auto wire = static_cast<uint8_t>((swapEnds(static_cast<uint8_t>(b)) ^ magic) + 1);
    forward_[b] = wire;
    backward_[wire] = static_cast<uint8_t>(b);
  }
}

Bytes Swizzle::operator()(const Bytes& bytes) const {
  Bytes out(bytes.size());
  std::transform(bytes.begin(), bytes.end(), out.begin(), [this](uint8_t b) { return forward_[b]; });
  return out;
}

Bytes Swizzle::undo(const Bytes& bytes) const {
  Bytes out(bytes.size());
  std::transform(bytes.begin(), bytes.end(), out.begin(), [this](uint8_t b) { return backward_[b]; });
  return out;
}

Bytes udpPacket(const Bytes& swizzled) {
  unsigned sum = 0;
  for (uint8_t b : swizzled) sum += b;
  Bytes packet(swizzled.size() + 2);
  packet[0] = static_cast<uint8_t>((sum >> 8) & 0xFF);
  packet[1] = static_cast<uint8_t>(sum & 0xFF);
  std::copy(swizzled.begin(), swizzled.end(), packet.begin() + 2);
  return packet;
}

Bytes checkedPayload(const Bytes& packet) {
  if (packet.size() < 3) return {};
  unsigned sum = 0;
  for (size_t i = 2; i < packet.size(); ++i) sum += packet[i];
  if (static_cast<uint16_t>(sum) != ((packet[0] << 8) | packet[1])) return {};
  return Bytes(packet.begin() + 2, packet.end());
}

void appendS14(Bytes& out, int value) {
  const int v = std::clamp(value, -8192, 8191) & 0x3FFF;
  out.push_back(static_cast<uint8_t>(v >> 7));
  out.push_back(static_cast<uint8_t>(v & 0x7F));
}

int readS14(const uint8_t* bytes) {
  const int v = ((bytes[0] & 0x7F) << 7) | (bytes[1] & 0x7F);
  return v >= 0x2000 ? v - 0x4000 : v;
}

void appendU35(Bytes& out, int64_t value) {
  const auto v = static_cast<uint64_t>(static_cast<uint32_t>(static_cast<int32_t>(value)));
  for (int shift = 28; shift >= 0; shift -= 7) out.push_back(static_cast<uint8_t>((v >> shift) & 0x7F));
}

int64_t readU35(const uint8_t* bytes) {
  uint64_t v = 0;
  for (int i = 0; i < 5; ++i) v = (v << 7) | (bytes[i] & 0x7F);
  return static_cast<int32_t>(static_cast<uint32_t>(v & 0xFFFFFFFFu));
}

void appendPower(Bytes& out, double percent) {
  const int raw = static_cast<int>(std::lround(std::clamp(percent, 0.0, 100.0) / 100 * kFullPower));
  out.push_back(static_cast<uint8_t>(raw >> 7));
  out.push_back(static_cast<uint8_t>(raw & 0x7F));
}

double readPower(const uint8_t* bytes) { return 100.0 * (((bytes[0] & 0x7F) << 7) | (bytes[1] & 0x7F)) / kFullPower; }

std::vector<Bytes> splitCommands(const Bytes& stream) {
  std::vector<Bytes> commands;
  for (uint8_t b : stream) {
    if (b & 0x80 || commands.empty()) commands.emplace_back();
    commands.back().push_back(b);
  }
  return commands;
}

}  // namespace rotafab::devices::ruida
