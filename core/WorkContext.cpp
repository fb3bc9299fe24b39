#include "core/WorkContext.h"

#include <spdlog/logger.h>

namespace rotafab::core {

void WorkContext::note(const std::string& text) const {
  if (log_) log_->info(text);
}

void WorkContext::warn(const std::string& text) const {
  if (log_) log_->warn(text);
}

}  // namespace rotafab::core
