#pragma once
// A refusal for the API's client: an HTTP status (4xx: the request; 5xx: the
// daemon) and one line, with any fields the error's JSON body has beside
// "error" (docs/API.md, "Errors").

#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

namespace rotafab::service {

class ApiError : public std::runtime_error {
 public:
  ApiError(int status, const std::string& message, nlohmann::json details = nullptr)
      : std::runtime_error(message), status(status), details(std::move(details)) {}
  int status;
  nlohmann::json details;  // fields the error's body has beside "error" (an object, or null)
};

}  // namespace rotafab::service
