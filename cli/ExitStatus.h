#pragma once
// The exit statuses (core/ExitCode.h), by their names in the command line's namespace.

#include "core/ExitCode.h"

namespace rotafab::cli {

using core::ExitCode;
using core::kDeviceFault;
using core::kSuccess;
using core::kUsageError;
using core::kUserError;

}  // namespace rotafab::cli
