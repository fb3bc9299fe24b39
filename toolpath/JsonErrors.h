#pragma once
// nlohmann-json's exceptions said for a user: their text without the
// library's tag ("[json.exception.parse_error.101] ").

#include <nlohmann/json.hpp>

#include <string>

namespace rotafab::jobs {

inline std::string jsonErrorText(const nlohmann::json::exception& error) {
  std::string text = error.what();
  if (text.starts_with("[json.exception.")) {
    if (const size_t end = text.find("] "); end != std::string::npos) text.erase(0, end + 2);
  }
  // "parse error at line 1, column 1: syntax error while parsing value - ..."
  if (text.starts_with("parse error at ")) text.erase(0, 15);
  return text;
}

}  // namespace rotafab::jobs
