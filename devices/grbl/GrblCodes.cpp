#include "devices/grbl/GrblCodes.h"

#include <fmt/format.h>

#include <map>

namespace rotafab::devices::grbl {

std::string errorMessage(int code) {
  static const std::map<int, const char*> kErrors{
      {1, "a G-code word has no letter"},
      {2, "a number is missing or malformed"},
      {3, "'$' system command not recognised"},
      {4, "a negative value where a positive one is expected"},
      {5, "homing is not enabled ($22)"},
      {6, "the step pulse must be at least 3 microseconds ($0)"},
      {7, "the settings in EEPROM could not be read; defaults restored"},
      {8, "'$' command only valid when idle"},
      {9, "G-code locked out during an alarm or jog; unlock ($X) or home ($H)"},
      {10, "soft limits need homing enabled ($20 needs $22)"},
      {11, "line too long: more characters than the controller takes"},
      {12, "step rate too high for this setting"},
      {13, "the safety door is open"},
      {14, "build info or startup line too long for EEPROM"},
      {15, "jog target beyond the machine's travel"},
      {16, "jog command without '=' or with a forbidden word"},
      {17, "laser mode needs PWM output on the spindle pin"},
      {20, "unsupported or invalid G-code command"},
      {21, "more than one command of the same modal group in a block"},
      {22, "feed rate not set"},
      {23, "a command needs an integer value"},
      {24, "two commands that both need axis words in one block"},
      {25, "a G-code word repeated in a block"},
      {26, "a command that needs axis words has none"},
      {27, "line number out of range"},
      {28, "a command is missing its P or L value"},
      {29, "G59.x work coordinate systems are not supported"},
      {30, "G53 needs G0 or G1 motion"},
      {31, "axis words in a block whose command does not use them"},
      {32, "G2/G3 arc without an axis word in its plane"},
      {33, "the motion target is invalid"},
      {34, "arc radius definition error"},
      {35, "G2/G3 arc without an offset word in its plane"},
      {36, "unused words left in the block"},
      {37, "tool length offset axis is not the configured one"},
      {38, "tool number above the maximum"},
  };
  const auto it = kErrors.find(code);
  return fmt::format("error:{} ({})", code, it == kErrors.end() ? "an error this driver does not know" : it->second);
}

std::string alarmMessage(int code) {
  static const std::map<int, const char*> kAlarms{
      {1, "hard limit triggered; position lost, home again"},
      {2, "motion target beyond the machine's travel (soft limit)"},
      {3, "reset while in motion; position lost, home again"},
      {4, "probe not in its expected initial state"},
      {5, "probe did not touch within its travel"},
      {6, "homing failed: reset during the cycle"},
      {7, "homing failed: the safety door opened during the cycle"},
      {8, "homing failed: the limit switch did not clear on pull-off"},
      {9, "homing failed: no limit switch within the search distance"},
  };
  const auto it = kAlarms.find(code);
  return fmt::format("ALARM:{} ({})", code, it == kAlarms.end() ? "an alarm this driver does not know" : it->second);
}

}  // namespace rotafab::devices::grbl
