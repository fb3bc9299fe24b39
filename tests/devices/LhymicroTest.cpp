// LHYMICRO-GL (the M2 Nano's language), checked against values the reference
// programs produce (MeerK40t's tests, K40 Whisperer's hard-coded packets) as
// collected in the protocol notes: CRCs, framing, distances, speed codes and
// line encodings.

#include "devices/m2nano/Lhymicro.h"

#include <gtest/gtest.h>

#include <cstring>

namespace rotafab::devices::m2nano {
namespace {

uint8_t crcOf(const std::string& text) { return packet(text)[33]; }

TEST(Lhymicro, PacketCrcsMatchTheReferencePackets) {
  EXPECT_EQ(crcOf(""), 0x50);      // all 'F'
  EXPECT_EQ(crcOf("I"), 0x82);     // K40 Whisperer's emergency stop
  EXPECT_EQ(crcOf("IPP"), 0xE4);   // its home
  EXPECT_EQ(crcOf("IS2P"), 0x0F);  // its unlock
  EXPECT_EQ(crcOf("PN"), 0xF3);
  EXPECT_EQ(crcOf("ABCDEFGHIJKLMNOPQRSTUVWXYZ0123"), 0x3C);
  const char* check = "123456789";  // CRC-8/MAXIM's check value
  EXPECT_EQ(crc8(reinterpret_cast<const uint8_t*>(check), std::strlen(check)), 0xA1);
  const Packet home = packet("IPP");
  EXPECT_EQ(home[0], 0xA6);
  EXPECT_EQ(home[1], 0x00);
  EXPECT_EQ(std::string(home.begin() + 2, home.begin() + 32), "IPP" + std::string(27, 'F'));
  EXPECT_EQ(home[32], 0xA6);
  EXPECT_EQ(home[33], 0xE4);
  // A CRC can be 0xA6 itself: frames are read by position, never split at 0xA6.
  EXPECT_EQ(crcOf("ICV1752231021000191NRBS1EDzzz2"), 0xA6);
  // A line longer than 30 bytes spans packets; only the last is padded.
  const auto square = packets("ICV2502451021000015CNRBS1EDzzz235Rzzz235Tzzz235Lzzz235FNSE");
  ASSERT_EQ(square.size(), 2u);
  EXPECT_EQ(square[0][33], 0x14);
  EXPECT_EQ(square[1][33], 0x14);
}

TEST(Lhymicro, Distances) {
  const std::pair<long, const char*> table[] = {
      {0, ""},     {1, "a"},         {25, "y"},     {26, "|a"},    {50, "|y"},         {51, "|z"},
      {52, "052"}, {254, "254"},     {255, "z"},    {256, "za"},   {300, "z|t"},       {307, "z052"},
      {510, "zz"}, {1000, "zzz235"}, {787, "zzzv"}, {394, "z139"}, {1575, "zzzzzz|t"}, {2000, "zzzzzzz215"}};
  for (const auto& [mils, text] : table) EXPECT_EQ(distance(mils), text) << mils;
}

TEST(Lhymicro, SpeedCodesOfTheM2Board) {
  EXPECT_EQ(speedCode(15), "CV2490731016000027C");  // MeerK40t's test
  EXPECT_EQ(speedCode(10), "CV2452421011000060C");  // MeerK40t's test
  EXPECT_EQ(speedCode(20), "CV2502451021000015C");
  EXPECT_EQ(speedCode(5), "CV2352371006000223C");
  EXPECT_EQ(speedCode(1), "CV1551941002013022C");
}

TEST(Lhymicro, LinesInCompactMode) {
  const auto line = [](long dx, long dy) {
    CompactState state;
    return compactLine(dx, dy, true, state);
  };
  EXPECT_EQ(line(1000, 0), "Dzzz235");
  EXPECT_EQ(line(100, 100), "MD100");
  EXPECT_EQ(line(10, 4), "DaMaBaMaBbMaBaMaBa");
  EXPECT_EQ(line(7, -3), "DaLMaBaMaBaMaBa");
  EXPECT_EQ(line(3, 10), "RDaMaRbMaRcMaRa");
  // The state carries: a second line along the same axis needs no letter, a turn does.
  CompactState state;
  EXPECT_EQ(compactLine(0, 1000, true, state), "RDzzz235");
  EXPECT_EQ(compactLine(0, 5, true, state), "e");
  EXPECT_EQ(compactLine(-5, 0, false, state), "TUe");
}

// A one-inch square on a 15 in bed at 20 mm/s: home, compact mode, a dark
// move to its corner (diagonal, so the first side states its B again), the
// four sides lit, finish, home; and the .egv header.
TEST(Lhymicro, AJobForOneSheet) {
  jobs::Toolpath path;
  path.width = path.height = 15;
  jobs::ToolpathStroke square;
  square.speed = 20 / 25.4;
  square.points = {{1, 14}, {2, 14}, {2, 13}, {1, 13}, {1, 14}};  // y up: the board's (1000,1000) to (2000,2000)
  path.strokes.push_back(square);
  const auto lines = jobLines(path);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0], "IPP");
  EXPECT_EQ(lines[1], "ICV2502451021000015CNRBS1EMzzz235BDzzz235Rzzz235Tzzz235Lzzz235UFNSE");
  // A second stroke at another speed: the first section ends "@NSE", the next states its speed and directions.
  jobs::ToolpathStroke faster = square;
  faster.speed = 10 / 25.4;
  path.strokes.push_back(faster);
  const auto two = jobLines(path);
  ASSERT_EQ(two.size(), 3u);
  EXPECT_TRUE(two[1].ends_with("Lzzz235U@NSE")) << two[1];
  EXPECT_TRUE(two[2].starts_with("CV2452421011000060CNRBS1E")) << two[2];
  EXPECT_TRUE(two[2].ends_with("UFNSE")) << two[2];
  path.strokes[0].points[0] = {16, 14};
  EXPECT_THROW(jobLines(path), std::invalid_argument);
  const std::string egv = egvFile(lines);
  EXPECT_EQ(egv.rfind("Document type : LHYMICRO-GL file\nFile version: 1.0.01\nCopyright: Unknown\n"
                      "Creator-Software: rotafab\n\n%0%0%0%0%\nIPP\n",
                      0),
            0u);
  EXPECT_TRUE(egv.ends_with("UFNSE\n"));
}

}  // namespace
}  // namespace rotafab::devices::m2nano
