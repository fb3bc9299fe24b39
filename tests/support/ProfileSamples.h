#pragma once
// A machine profile that loads, and a way to break it one key at a time.

#include <gtest/gtest.h>

#include <string>

namespace rotafab::test {

inline constexpr const char* kGoodMachine =
    "kind: machine\n"                                                       // 1
    "name: test\n"                                                          // 2
    "bed: {width: 32in, height: 18in, margin: 0.25in}\n"                    // 3
    "driver: spool\n"                                                       // 4
    "connection: spool:out\n"                                               // 5
    "colours:\n"                                                            // 6
    "  blue: {rgb: [0, 0, 255], power: 50}\n"                               // 7
    "  red: {rgb: [255, 0, 0]}\n"                                           // 8
    "  yellow: {rgb: '#ffff00'}\n"                                          // 9
    "  green: {rgb: [0, 255, 0]}\n"                                         // 10
    "operations: {cut: blue, score: red, etch: yellow, outline: green}\n";  // 11

// `text` with its first `from` replaced by `to` (a test fails if there is none).
inline std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

}  // namespace rotafab::test
