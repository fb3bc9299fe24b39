#pragma once
// Bad input or a bad value of an option: one line for the person who gave
// it, naming the file and the element or the option, shown as it is (the
// command line prints it after "error: " and exits with status 1; the
// daemon answers it with a 4xx status).

#include <stdexcept>

namespace rotafab::core {

class UserError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace rotafab::core
