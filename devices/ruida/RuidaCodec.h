#pragma once
// The bytes of a Ruida controller (RDC6442, RDC6445, 634XG: most fab labs'
// CO2 lasers), as the public descriptions give them (edutechwiki's "Ruida"
// page, kkaempf/ruida's doc/commands.md, MeerK40t's meerk40t/ruida; learnt
// from them, written anew): every byte "swizzled" with the controller's
// magic number, numbers in 7-bit bytes (only a command's first byte has
// its top bit set), lengths in micrometres, and over UDP each packet
// behind a 16-bit checksum of its swizzled bytes.

#include <cstdint>
#include <string_view>
#include <vector>

namespace rotafab::devices::ruida {

using Bytes = std::vector<uint8_t>;

// Lengths on the wire are micrometres.
inline constexpr double kMicrometresPerInch = 25400;

// The magic number most controllers scramble with; the 634XG's is 0x11.
inline constexpr uint8_t kDefaultMagic = 0x88;

// The controller's one-byte answers to a UDP packet (before swizzling):
// taken, refused (send it again), and the keep-alive's.
inline constexpr uint8_t kAck = 0xCC, kNak = 0xCF, kError = 0xCD, kEnquire = 0xCE;

// The byte scrambling of the wire and of .rd files: bit 7 and bit 0
// swapped, XOR with the magic, plus one (mod 256); unswizzle undoes it.
class Swizzle {
 public:
  explicit Swizzle(uint8_t magic = kDefaultMagic);
  [[nodiscard]] uint8_t operator()(uint8_t byte) const { return forward_[byte]; }
  [[nodiscard]] uint8_t undo(uint8_t byte) const { return backward_[byte]; }
  [[nodiscard]] Bytes operator()(const Bytes& bytes) const;
  [[nodiscard]] Bytes undo(const Bytes& bytes) const;
  [[nodiscard]] uint8_t magic() const { return magic_; }

 private:
  uint8_t magic_;
  uint8_t forward_[256];
  uint8_t backward_[256];
};

// A UDP packet: the big-endian 16-bit sum of the swizzled payload, then the payload.
Bytes udpPacket(const Bytes& swizzled);
// The payload of a packet whose checksum holds, else empty (a packet of no
// payload is not one the controller takes either).
Bytes checkedPayload(const Bytes& packet);

// A signed 14-bit number in two 7-bit bytes, most significant first (a
// relative move, in micrometres: -8192 to 8191).
void appendS14(Bytes& out, int value);
int readS14(const uint8_t* bytes);
// A 35-bit number in five 7-bit bytes (an absolute position in
// micrometres, a speed in micrometres a second); a negative value is
// written as its 32-bit two's complement.
void appendU35(Bytes& out, int64_t value);
int64_t readU35(const uint8_t* bytes);  // sign-extended from 32 bits
// A power, percent of full, as 14 bits (100% is 0x3FFF).
void appendPower(Bytes& out, double percent);
double readPower(const uint8_t* bytes);

// The commands of a stream: it is cut before each byte with its top bit
// set (a command's first byte; every operand byte is below 0x80).
std::vector<Bytes> splitCommands(const Bytes& stream);

}  // namespace rotafab::devices::ruida
