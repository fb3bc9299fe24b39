// The Ruida controller's bytes, checked against values worked by hand from
// the public descriptions of the protocol (edutechwiki's "Ruida" page,
// kkaempf/ruida's doc/commands.md) and bytes of files LightBurn writes.

#include "devices/ruida/RuidaCodec.h"
#include "devices/ruida/RuidaJob.h"

#include <gtest/gtest.h>

#include <random>
#include <stdexcept>
#include <string>

namespace rotafab::devices::ruida {
namespace {

TEST(RuidaCodec, TheSwizzleOfEachMagicIsUndoneAndMatchesTheWire) {
  const Swizzle usual, thunder(0x11);
  EXPECT_EQ(usual(0x00), 0x89);  // the magic plus one: how a file's magic shows
  EXPECT_EQ(usual(kAck), 0xC6);
  EXPECT_EQ(usual(kNak), 0x48);
  EXPECT_EQ(usual(0xDA), 0xD4);
  EXPECT_EQ(thunder(kAck), 0x5D);
  // An .rd file of RDWorks begins D8 12 F0: D2 9B FA on the wire with 0x88, 49 04 61 with 0x11.
  EXPECT_EQ(usual(Bytes{0xD8, 0x12, 0xF0}), (Bytes{0xD2, 0x9B, 0xFA}));
  EXPECT_EQ(thunder(Bytes{0xD8, 0x12, 0xF0}), (Bytes{0x49, 0x04, 0x61}));
  for (int magic = 0; magic < 256; ++magic) {
    const Swizzle swizzle(static_cast<uint8_t>(magic));
    for (int b = 0; b < 256; ++b) ASSERT_EQ(swizzle.undo(swizzle(static_cast<uint8_t>(b))), b) << magic;
  }
}

// The status read DA 00 04 00 as a UDP packet: its swizzled bytes behind
// their big-endian sum; a packet whose sum is wrong yields nothing.
TEST(RuidaCodec, APacketCarriesTheSumOfItsSwizzledBytes) {
  const Bytes packet = udpPacket(Swizzle()(Bytes{0xDA, 0x00, 0x04, 0x00}));
  EXPECT_EQ(packet, (Bytes{0x02, 0x73, 0xD4, 0x89, 0x8D, 0x89}));
  EXPECT_EQ(Swizzle().undo(checkedPayload(packet)), (Bytes{0xDA, 0x00, 0x04, 0x00}));
  Bytes corrupt = packet;
  corrupt[3] ^= 0x01;
  EXPECT_TRUE(checkedPayload(corrupt).empty());
  EXPECT_TRUE(checkedPayload(Bytes{0x00, 0x00}).empty());
}

TEST(RuidaCodec, NumbersInSevenBitBytes) {
  Bytes out;
  appendS14(out, -1000);
  EXPECT_EQ(out, (Bytes{0x78, 0x18}));
  for (int v : {-8192, -8191, -1, 0, 1, 8191}) {
    Bytes b;
    appendS14(b, v);
    EXPECT_EQ(readS14(b.data()), v);
  }
  out.clear();
  appendU35(out, 100000);  // 100 mm in micrometres
  EXPECT_EQ(out, (Bytes{0x00, 0x00, 0x06, 0x0D, 0x20}));
  for (int64_t v : {int64_t{0}, int64_t{10000}, int64_t{-1}, int64_t{2000000000}, int64_t{-123456}}) {
    Bytes b;
    appendU35(b, v);
    EXPECT_EQ(readU35(b.data()), v);
    for (uint8_t byte : b) EXPECT_LT(byte, 0x80);
  }
  // Powers as LightBurn writes them: 10% is 0C 66, 20% is 19 4D, 100% is 7F 7F.
  out.clear();
  appendPower(out, 10);
  appendPower(out, 20);
  appendPower(out, 100);
  EXPECT_EQ(out, (Bytes{0x0C, 0x66, 0x19, 0x4D, 0x7F, 0x7F}));
  EXPECT_NEAR(readPower(out.data() + 2), 20, 0.01);
}

TEST(RuidaCodec, AStreamSplitsIntoCommandsAtEachTopBit) {
  // Move to (10 mm, 20 mm), cut to (30 mm, 20 mm), end of file.
  Bytes stream{0x88};
  appendU35(stream, 10000);
  appendU35(stream, 20000);
  stream.push_back(0xA8);
  appendU35(stream, 30000);
  appendU35(stream, 20000);
  stream.push_back(0xD7);
  const auto commands = splitCommands(stream);
  ASSERT_EQ(commands.size(), 3u);
  EXPECT_EQ(commands[0], (Bytes{0x88, 0x00, 0x00, 0x00, 0x4E, 0x10, 0x00, 0x00, 0x01, 0x1C, 0x20}));
  EXPECT_EQ(readU35(commands[1].data() + 1), 30000);
  EXPECT_EQ(commands[2], Bytes{0xD7});
}

// A sheet's toolpath as a job and back: every stroke where it was, at its
// power and speed, a long step absolute and a short one relative, every
// operand below 0x80, and the file sum that the trailer gives.
TEST(RuidaJob, AToolpathIsEncodedAndDecodedStrokeForStroke) {
  jobs::Toolpath toolpath;
  toolpath.width = 15.75, toolpath.height = 15.75;
  const auto stroke = [](double power, double speed, std::vector<jobs::Point2> points) {
    jobs::ToolpathStroke s;
    s.power = power, s.speed = speed, s.points = std::move(points);
    return s;
  };
  toolpath.strokes = {stroke(0.2, 4, {{1, 1}, {1.2, 1}, {1.2, 1.1}}),
                      stroke(0.6, 0.5, {{2, 2}, {12, 2}, {12, 9}, {2, 9}, {2, 2}}),  // 254 mm sides: absolute
                      stroke(0.2, 4, {{3, 3}, {3.01, 3.02}})};
  const Bytes stream = jobStream(toolpath);
  ASSERT_EQ(stream.back(), 0xD7);
  const auto commands = splitCommands(stream);
  for (const Bytes& c : commands) {
    for (size_t i = 1; i < c.size(); ++i) ASSERT_LT(c[i], 0x80) << "an operand with its top bit set";
  }
  const auto count = [&](uint8_t op) {
    return std::count_if(commands.begin(), commands.end(), [op](const Bytes& c) { return c[0] == op; });
  };
  EXPECT_EQ(count(0x88), 3);  // the first move, and the two beyond 8.191 mm
  EXPECT_EQ(count(0xA8), 4);  // the square's sides
  EXPECT_EQ(count(0xAA), 1);  // 5.08 mm along x
  EXPECT_EQ(count(0xAB), 1);  // 2.54 mm along y
  EXPECT_EQ(count(0xA9), 1);  // a short diagonal
  const DecodedJob decoded = decodeJob(stream, toolpath.height);
  EXPECT_TRUE(decoded.ended);
  EXPECT_TRUE(decoded.sumHolds);
  ASSERT_EQ(decoded.strokes.size(), toolpath.strokes.size());
  for (size_t s = 0; s < toolpath.strokes.size(); ++s) {
    const auto& want = toolpath.strokes[s];
    const auto& got = decoded.strokes[s];
    EXPECT_NEAR(got.power, want.power, 1e-4) << s;
    EXPECT_NEAR(got.speed, want.speed, 1e-4) << s;
    ASSERT_EQ(got.points.size(), want.points.size()) << s;
    for (size_t i = 0; i < want.points.size(); ++i) {
      EXPECT_NEAR(got.points[i].x(), want.points[i].x(), 1e-4) << s << ":" << i;
      EXPECT_NEAR(got.points[i].y(), want.points[i].y(), 1e-4) << s << ":" << i;
    }
  }
  // A byte changed in the body: the sum no longer holds.
  Bytes changed = stream;
  changed[changed.size() - 20] ^= 0x01;
  EXPECT_FALSE(decodeJob(changed, toolpath.height).sumHolds);
}

// A simulator decodes whatever arrives: torn, cut short or random streams
// are read without a crash (the sanitizers' pass checks every read), and a
// command cut short is named.
TEST(RuidaJob, AnyStreamIsDecodedOrRefusedByName) {
  std::mt19937 random(7);
  std::uniform_int_distribution<int> byte(0, 255), length(0, 64);
  for (int i = 0; i < 2000; ++i) {
    Bytes stream(static_cast<size_t>(length(random)));
    for (uint8_t& b : stream) b = static_cast<uint8_t>(byte(random));
    try {
      (void)decodeJob(stream, 10);
    } catch (const std::invalid_argument& error) {
      EXPECT_NE(std::string(error.what()).find("command "), std::string::npos) << error.what();
    }
  }
  EXPECT_THROW(decodeJob(Bytes{0x88, 0x00, 0x01}, 10), std::invalid_argument);
}

}  // namespace
}  // namespace rotafab::devices::ruida
