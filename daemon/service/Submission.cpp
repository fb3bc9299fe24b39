#include "daemon/service/Submission.h"

#include <fmt/format.h>

#include "daemon/service/ApiError.h"
#include "daemon/service/ApiInput.h"

namespace rotafab::service {
using nlohmann::json;

std::optional<jobs::MakeOptions> makeOptionsOf(const json& options) {
  if (options.is_null() || ((options.is_array() || options.is_object()) && options.empty())) return std::nullopt;
  if (!options.is_array() && !options.is_object()) {
    throw ApiError(400, "options: expected an object of options or a list of words");
  }
  constexpr size_t kMostOptions = 200;
  if (options.size() > kMostOptions) throw ApiError(400, fmt::format("options: more than {} given", kMostOptions));
  // Every name and text checked as any text a request brings, before make's table reads them.
  for (const auto& [key, value] : options.items()) {
    if (options.is_object()) (void)checkedText(json(key), "options", 100);
    if (value.is_string()) (void)checkedText(value, options.is_object() ? "options." + key : "options", 1000);
  }
  try {
    return jobs::submittedOptions(options);
  } catch (const jobs::OptionError& error) {
    throw ApiError(400, fmt::format("make options: {}", error.what()));
  }
}

}  // namespace rotafab::service
